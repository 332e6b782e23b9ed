//! The Moravec interest rows: for each of the four shifts the squared differences are summed
//! down a `k`-row column (a sliding sum: the row entering the window is added and the row
//! leaving it taken away, both recomputed from the image on the AVX paths; the portable path
//! keeps each row's squares in a ring instead), then across `k` columns; the interest is the
//! smallest of the four. Rows stream out one at a time to a [`RowSink`], so the whole
//! pass runs in the first-level cache.

use crate::image::{Gray, Rect};
use crate::simd::Path;

/// The four shifts: right, down, and the two diagonals.
pub(super) const SHIFTS: [(isize, isize); 4] = [(1, 0), (0, 1), (1, 1), (1, -1)];

/// Where interest rows go: the row buffer for row `y` (the window's full width), then word that
/// it is filled.
pub(super) trait RowSink {
    fn row(&mut self, y: usize) -> &mut [u32];
    fn done(&mut self, y: usize);
}

/// Scratch: one column sum per shift and column.
#[derive(Debug, Default)]
pub(super) struct Columns {
    sums: Vec<u32>,
    /// The portable path's squares (16 bits) of the last `k` rows per shift, row `r` in slot
    /// `r % k` (shift `d`'s at `d * k`), and of the row entering the window.
    ring: Vec<Vec<u16>>,
    enter: Vec<u16>,
}

/// The margin (pixels) of a `k x k` window where the interest is not defined (it is 0 there):
/// the shifted window must stay inside.
fn margin(k: usize) -> usize {
    k / 2 + 1
}

/// Streams every row of `w` (0 in the margins) to `sink`, top to bottom, on `path` (one the
/// CPU has). The body is portable code the compiler vectorises, compiled once per path.
pub(super) fn interest_rows(
    path: Path,
    img: &Gray<'_>,
    w: Rect,
    k: usize,
    cols: &mut Columns,
    sink: &mut impl RowSink,
) {
    match Path::clamp(path) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU has the path's features (clamped).
        Path::Avx512 => unsafe { rows_avx512(img, w, k, cols, sink) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Path::Avx2 => unsafe { rows_avx2(img, w, k, cols, sink) },
        _ => rows::<true>(img, w, k, cols, sink),
    }
}

/// [`rows`] compiled for AVX-512.
///
/// # Safety
/// The CPU must have the features of [`Path::Avx512`].
#[multiversion::target("x86_64+avx2+fma+bmi2+avx512f+avx512bw+avx512vnni")]
unsafe fn rows_avx512(img: &Gray<'_>, w: Rect, k: usize, cols: &mut Columns, sink: &mut impl RowSink) {
    rows::<false>(img, w, k, cols, sink)
}

/// [`rows`] compiled for AVX2.
///
/// # Safety
/// The CPU must have the features of [`Path::Avx2`].
#[multiversion::target("x86_64+avx2+fma+bmi2")]
unsafe fn rows_avx2(img: &Gray<'_>, w: Rect, k: usize, cols: &mut Columns, sink: &mut impl RowSink) {
    rows::<false>(img, w, k, cols, sink)
}

/// `(p - q)²`: at most 255², which fits 16 bits, so it is formed in 16-bit lanes.
#[inline(always)]
fn sq16(p: u8, q: u8) -> u16 {
    let d = i16::from(p) - i16::from(q);
    d.wrapping_mul(d) as u16
}

/// [`sq16`] widened for a sum.
#[inline(always)]
fn sq(p: u8, q: u8) -> u32 {
    u32::from(sq16(p, q))
}

/// Image row `y` and the same row shifted by `(dx, dy)`, columns `x0 .. x0 + n`.
#[inline(always)]
fn pair<'a>(img: &Gray<'a>, y: usize, x0: usize, n: usize, (dx, dy): (isize, isize)) -> (&'a [u8], &'a [u8]) {
    let a = &img.row(y)[x0..x0 + n];
    let b = &img.row(y.wrapping_add_signed(dy))[x0.wrapping_add_signed(dx)..][..n];
    (a, b)
}

/// The interest rows. `STAGED` (the portable path): each row's squares are formed in a loop of
/// their own, as 16-bit values, and kept in a ring of the last `k` rows per shift, so the row
/// leaving the window is not squared again. In one loop with the 32-bit sums LLVM widened four
/// pixels at a time at the SSE2 baseline, each 16-bit multiply filling half a register; on their
/// own the squares are formed eight to a register. The AVX paths keep the one loop (the ring
/// has not been measured there).
#[inline(always)]
fn rows<const STAGED: bool>(img: &Gray<'_>, w: Rect, k: usize, cols: &mut Columns, sink: &mut impl RowSink) {
    let (ww, wh, h, mg) = (w.width(), w.height(), k / 2, margin(k));
    if ww <= 2 * mg || wh <= 2 * mg {
        for y in 0..wh {
            sink.row(y).fill(0);
            sink.done(y);
        }
        return;
    }
    // Columns whose shifted pixels stay inside: 1 .. ww - 1; centres: mg .. ww - mg.
    let (x0, n) = (w.x0 + 1, ww - 2);
    let m = n - 2 * h;
    cols.sums.clear();
    cols.sums.resize(SHIFTS.len() * n, 0);
    if STAGED {
        cols.ring.resize_with(SHIFTS.len() * k, Vec::new);
    }
    let top = 1; // the first row a window covers (row 0 is read by the up-right shift)
    for y in 0..mg {
        sink.row(y).fill(0);
        sink.done(y);
    }
    for y in mg..wh - mg {
        let out = sink.row(y);
        out[..mg].fill(0);
        out[ww - mg..].fill(0);
        let centres = &mut out[mg..mg + m];
        for (d, &shift) in SHIFTS.iter().enumerate() {
            let c = &mut cols.sums[d * n..(d + 1) * n];
            if y == mg {
                for r in top..top + k {
                    let (a, b) = pair(img, w.y0 + r, x0, n, shift);
                    for ((s, &p), &q) in c.iter_mut().zip(a).zip(b) {
                        *s += sq(p, q);
                    }
                    if STAGED {
                        let slot = &mut cols.ring[d * k + r % k];
                        slot.clear();
                        slot.extend(a.iter().zip(b).map(|(&p, &q)| sq16(p, q)));
                    }
                }
            } else if STAGED {
                // The row leaving the window (y - h - 1) is k rows above the one entering it
                // (y + h): its squares are in the slot the entering row's take.
                let (a, b) = pair(img, w.y0 + y + h, x0, n, shift);
                cols.enter.clear();
                cols.enter.extend(a.iter().zip(b).map(|(&p, &q)| sq16(p, q)));
                let slot = &mut cols.ring[d * k + (y + h) % k];
                for ((s, &p), &q) in c.iter_mut().zip(&cols.enter).zip(slot.iter()) {
                    *s = s.wrapping_add(u32::from(p)).wrapping_sub(u32::from(q));
                }
                std::mem::swap(slot, &mut cols.enter);
            } else {
                let (a, b) = pair(img, w.y0 + y + h, x0, n, shift);
                let (e, f) = pair(img, w.y0 + y - h - 1, x0, n, shift);
                for ((((s, &p), &q), &u), &v) in c.iter_mut().zip(a).zip(b).zip(e).zip(f) {
                    *s = s.wrapping_add(sq(p, q)).wrapping_sub(sq(u, v));
                }
            }
        }
        match k {
            3 => across::<3>(&cols.sums, n, centres),
            5 => across::<5>(&cols.sums, n, centres),
            7 => across::<7>(&cols.sums, n, centres),
            _ => across_any(&cols.sums, n, k, centres),
        }
        sink.done(y);
    }
    for y in wh - mg..wh {
        sink.row(y).fill(0);
        sink.done(y);
    }
}

/// `out[x]` = the least over the four shifts of `Σ c[x .. x + K]`, where `sums` holds the four
/// shifts' `n` column sums one after another.
#[inline(always)]
fn across<const K: usize>(sums: &[u32], n: usize, out: &mut [u32]) {
    let m = out.len();
    let taps: [[&[u32]; K]; 4] = std::array::from_fn(|d| std::array::from_fn(|j| &sums[d * n + j..][..m]));
    for (x, o) in out.iter_mut().enumerate() {
        // A window sum is at most 81 * 255² (23 bits), so the least is taken as `i32`: SSE2
        // compares signed 32-bit lanes (`pcmpgtd`) but not unsigned ones.
        let mut best = i32::MAX;
        for shift in &taps {
            let mut s = 0u32;
            for t in shift {
                s += t[x];
            }
            best = best.min(s as i32);
        }
        *o = best as u32;
    }
}

/// [`across`] for a window size without its own instance (9).
fn across_any(sums: &[u32], n: usize, k: usize, out: &mut [u32]) {
    for (x, o) in out.iter_mut().enumerate() {
        *o = (0..4).map(|d| sums[d * n + x..][..k].iter().sum::<u32>()).min().unwrap_or(0);
    }
}
