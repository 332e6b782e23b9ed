//! The passes of normalised correlation (`nc.rs`) around the cross-sum (`cross.rs`): the patch
//! sums of every placement with an upper bound of its score per block, and the scores of a
//! list of blocks. Each is one body compiled for each [`Path`]; the scores are the same `f32`
//! operations on the same exact integers on every path, so they agree bit for bit.
//!
//! The bound: with `S_P = ΣP`, `S_T = ΣT`, the score is `2 ΣPT S_P S_T / (ΣP² S_T² + ΣT² S_P²)`
//! and Cauchy-Schwarz gives `ΣPT <= sqrt(ΣP² ΣT²)`, so the score is at most `2 sqrt(ab) / (a + b)`
//! with `a = ΣP² S_T²`, `b = ΣT² S_P²`: 1 only for a patch whose contrast (`ΣP² / S_P²`) equals the
//! template's. It needs no cross-sum, and a block whose bound is below a score already found
//! cannot hold the best placement.

use crate::cross::{BLOCK_X, BLOCK_Y, origin};
use crate::simd::Path;

/// Per-template constants of the score.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Consts {
    st: f32,
    stt: f32,
    st2: f32,
    /// Template pixels, and the template's `1 + c_T²`, for the bound.
    n: f32,
    one_ct2: f32,
    /// Template width and height.
    tw: usize,
    th: usize,
}

impl Consts {
    pub(crate) fn new(sum: f64, sum_sq: f64, tw: usize, th: usize) -> Self {
        let st = sum as f32;
        let n = (tw * th) as f64;
        let one_ct2 = (n * sum_sq / (sum * sum)) as f32;
        Self { st, stt: sum_sq as f32, st2: st * st, n: n as f32, one_ct2, tw, th }
    }
}

/// The score of a placement from its sums (the one formula every path and pass uses).
#[inline(always)]
pub(crate) fn nc(k: &Consts, sp: f32, spp: f32, cross: i32) -> f32 {
    let spt = cross as f32 + 128.0 * sp;
    // A black patch (S_P = 0) has numerator 0 too: it scores 0.
    let den = (spp * k.st2 + k.stt * sp * sp).max(f32::MIN_POSITIVE);
    2.0 * spt * sp * k.st / den
}

/// A patch's `1 + c_P²` (`N ΣP² / S_P²`, `c_P` its coefficient of variation), on which alone its
/// score bound depends: a black patch gives 0 (its bound is then taken at `c_P = 0`).
#[inline(always)]
fn spread(k: &Consts, sp: f32, spp: f32) -> f32 {
    k.n * spp / (sp * sp).max(f32::MIN_POSITIVE)
}

/// The square of the score bound of a block whose patches' `1 + c_P²` lie in `[lo, hi]`:
/// `2 (1 + c_P c_T) / (2 + c_P² + c_T²)`, largest (1) at `c_P = c_T` and falling on either side,
/// so taken at the `c_P` of the interval nearest `c_T`. The interval is first widened by 1e-5 of
/// itself, well over the rounding of `spread` (a few units in 2^-24).
pub(crate) fn block_bound(k: &Consts, lo: f32, hi: f32) -> f32 {
    let (lo, hi) = (f64::from(lo) * (1.0 - 1e-5), f64::from(hi) * (1.0 + 1e-5));
    let ct2 = f64::from(k.one_ct2) - 1.0;
    let cp2 = (ct2 + 1.0).clamp(lo, hi.max(lo)) - 1.0;
    let (cp, ct) = (cp2.max(0.0).sqrt(), ct2.max(0.0).sqrt());
    let u = 2.0 * (1.0 + cp * ct) / (2.0 + cp2.max(0.0) + ct2);
    (u * u) as f32
}

/// Whether a block whose squared bound is `bound` can hold a score of at least `score`. The
/// margin (1e-4 on the square) is far above the `f32` rounding of the bound and the score (a
/// few units in 1e-7), so a block left out holds no score equal to or above `score`.
#[inline(always)]
pub(crate) fn may_reach(bound: f32, score: f32) -> bool {
    let s = score.max(0.0);
    bound * (1.0 + 1e-4) >= s * s
}

/// Patch sums of every placement (`nx x ny`, row-major, exact integers as `f32`) and each
/// block's squared score bound.
#[derive(Debug, Default)]
pub(crate) struct Sums {
    pub(crate) sp: Vec<f32>,
    pub(crate) spp: Vec<f32>,
    /// Per block: the squared score bound, after [`Sums::fill`].
    pub(crate) bound: Vec<f32>,
    /// Per block: the least and greatest `spread` of its patches.
    lo: Vec<f32>,
    hi: Vec<f32>,
    row_lo: Vec<f32>,
    row_hi: Vec<f32>,
    col_sums: Vec<u32>,
    col_squares: Vec<u32>,
    run_sums: Vec<u32>,
    run_squares: Vec<u32>,
}

/// Where the sums pass reads: the window's rows `pw` bytes apart, `ww` pixels wide.
pub(crate) struct Window<'a> {
    pub(crate) pad: &'a [u8],
    pub(crate) pw: usize,
    pub(crate) ww: usize,
    pub(crate) nx: usize,
    pub(crate) ny: usize,
}

impl Sums {
    /// Fills the sums and bounds of every placement of a `k.tw x k.th` template in `w`.
    pub(crate) fn fill(&mut self, path: Path, w: &Window<'_>, k: &Consts) {
        match Path::clamp(path) {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has the path's features (clamped).
            Path::Avx512 => unsafe { sums_avx512(self, w, k) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Path::Avx2 => unsafe { sums_avx2(self, w, k) },
            _ => sums(self, w, k),
        }
        for ((b, &lo), &hi) in self.bound.iter_mut().zip(&self.lo).zip(&self.hi) {
            *b = block_bound(k, lo, hi);
        }
    }
}

/// Column sums over the template's height slide down a row at a time; running sums along the
/// row give each placement's `S_P` and `ΣP²` as a difference (wrapping: only differences are
/// used, and window sums stay below 2^31, at most 128 x 128 x 255², so they convert as `i32`).
#[inline(always)]
fn sums(s: &mut Sums, w: &Window<'_>, k: &Consts) {
    let (nx, ny, ww, pw) = (w.nx, w.ny, w.ww, w.pw);
    let nbx = nx.div_ceil(BLOCK_X);
    for v in [&mut s.sp, &mut s.spp] {
        v.resize(nx * ny, 0.0);
    }
    let nb = nbx * ny.div_ceil(BLOCK_Y);
    s.bound.resize(nb, 0.0);
    for v in [&mut s.lo, &mut s.hi] {
        v.resize(nb, 0.0);
    }
    for v in [&mut s.row_lo, &mut s.row_hi] {
        v.resize(nx, 0.0);
    }
    for v in [&mut s.col_sums, &mut s.col_squares] {
        v.clear();
        v.resize(ww, 0);
    }
    for v in [&mut s.run_sums, &mut s.run_squares] {
        v.clear();
        v.resize(ww + 1, 0);
    }
    for r in 0..k.th {
        add_row(&mut s.col_sums, &mut s.col_squares, &w.pad[r * pw..r * pw + ww]);
    }
    for y in 0..ny {
        if y > 0 {
            let (old, new) = ((y - 1) * pw, (y - 1 + k.th) * pw);
            slide_row(&mut s.col_sums, &mut s.col_squares, &w.pad[old..old + ww], &w.pad[new..new + ww]);
        }
        running(&s.col_sums, &s.col_squares, &mut s.run_sums[1..], &mut s.run_squares[1..]);
        let (sp, spp) = (&mut s.sp[y * nx..(y + 1) * nx], &mut s.spp[y * nx..(y + 1) * nx]);
        let (lo, hi) = (&s.run_sums[..nx], &s.run_sums[k.tw..k.tw + nx]);
        let (qlo, qhi) = (&s.run_squares[..nx], &s.run_squares[k.tw..k.tw + nx]);
        for x in 0..nx {
            sp[x] = hi[x].wrapping_sub(lo[x]) as i32 as f32;
            spp[x] = qhi[x].wrapping_sub(qlo[x]) as i32 as f32;
        }
        // Each column's least and greatest spread down the block's rows (lane-wise, so that it
        // vectorises), then across the block's columns on its last row.
        let lanes = s.row_lo.iter_mut().zip(s.row_hi.iter_mut()).zip(sp.iter().zip(spp.iter()));
        if y % BLOCK_Y == 0 {
            for ((l, h), (&a, &q)) in lanes {
                (*l, *h) = (spread(k, a, q), spread(k, a, q));
            }
        } else {
            for ((l, h), (&a, &q)) in lanes {
                let (v, ol, oh) = (spread(k, a, q), *l, *h);
                (*l, *h) = (if v < ol { v } else { ol }, if v > oh { v } else { oh });
            }
        }
        if y % BLOCK_Y == BLOCK_Y - 1 || y + 1 == ny {
            let row = y / BLOCK_Y * nbx..(y / BLOCK_Y + 1) * nbx;
            let (blo, bhi) = (&mut s.lo[row.clone()], &mut s.hi[row]);
            for (i, (bl, bh)) in blo.iter_mut().zip(bhi).enumerate() {
                let cols = i * BLOCK_X..((i + 1) * BLOCK_X).min(nx);
                *bl = s.row_lo[cols.clone()].iter().fold(f32::MAX, |m, &v| m.min(v));
                *bh = s.row_hi[cols].iter().fold(0.0, |m, &v| m.max(v));
            }
        }
    }
}

/// [`sums`] compiled for AVX-512.
///
/// # Safety
/// The CPU must have the features of [`Path::Avx512`].
#[multiversion::target("x86_64+avx2+fma+bmi2+avx512f+avx512bw+avx512vnni")]
unsafe fn sums_avx512(s: &mut Sums, w: &Window<'_>, k: &Consts) {
    sums(s, w, k)
}

/// [`sums`] compiled for AVX2 and FMA (which it does not fuse: the sums are the portable ones).
///
/// # Safety
/// The CPU must have the features of [`Path::Avx2`].
#[multiversion::target("x86_64+avx2+fma+bmi2")]
unsafe fn sums_avx2(s: &mut Sums, w: &Window<'_>, k: &Consts) {
    sums(s, w, k)
}

#[inline(always)]
fn add_row(sums: &mut [u32], squares: &mut [u32], row: &[u8]) {
    for ((s, q), &p) in sums.iter_mut().zip(squares.iter_mut()).zip(row) {
        *s += u32::from(p);
        *q += u32::from(p) * u32::from(p);
    }
}

#[inline(always)]
fn slide_row(sums: &mut [u32], squares: &mut [u32], old: &[u8], new: &[u8]) {
    for (((s, q), &o), &n) in sums.iter_mut().zip(squares.iter_mut()).zip(old).zip(new) {
        *s = s.wrapping_add(u32::from(n)).wrapping_sub(u32::from(o));
        *q = q.wrapping_add(u32::from(n) * u32::from(n)).wrapping_sub(u32::from(o) * u32::from(o));
    }
}

/// Running (wrapping) sums of `a` and `b` into `ra` and `rb` (two chains in one loop).
#[inline(always)]
fn running(a: &[u32], b: &[u32], ra: &mut [u32], rb: &mut [u32]) {
    let (mut sa, mut sb) = (0u32, 0u32);
    for (((oa, ob), &x), &y) in ra.iter_mut().zip(rb.iter_mut()).zip(a).zip(b) {
        sa = sa.wrapping_add(x);
        sb = sb.wrapping_add(y);
        (*oa, *ob) = (sa, sb);
    }
}

/// The best score so far and its placement (row-major index; the first of equal scores).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Best {
    pub(crate) score: f32,
    pub(crate) index: usize,
}

impl Default for Best {
    fn default() -> Self {
        Self { score: f32::MIN, index: usize::MAX }
    }
}

/// What the score pass reads and writes: cross sums with a row stride of `nx` rounded up to
/// [`BLOCK_X`], scores `nx` to a row.
pub(crate) struct Scoring<'a> {
    pub(crate) sums: &'a Sums,
    pub(crate) cross: &'a [i32],
    pub(crate) scores: &'a mut [f32],
    pub(crate) nx: usize,
    pub(crate) ny: usize,
}

/// Scores the placements of `blocks` into `s.scores`, keeping the best in `best`.
pub(crate) fn score_blocks(path: Path, s: Scoring<'_>, k: &Consts, blocks: &[u32], best: &mut Best) {
    match Path::clamp(path) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU has the path's features (clamped).
        Path::Avx512 => unsafe { score_avx512(s, k, blocks, best) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Path::Avx2 => unsafe { score_avx2(s, k, blocks, best) },
        _ => score(s, k, blocks, best),
    }
}

#[inline(always)]
fn score(s: Scoring<'_>, k: &Consts, blocks: &[u32], best: &mut Best) {
    let (nx, ny, stride) = (s.nx, s.ny, s.nx.next_multiple_of(BLOCK_X));
    for (y0, xb) in blocks.iter().map(|&b| origin(b as usize, nx)) {
        let n = BLOCK_X.min(nx - xb);
        for y in y0..(y0 + BLOCK_Y).min(ny) {
            let i = y * nx + xb;
            let (sp, spp, out) = (&s.sums.sp[i..i + n], &s.sums.spp[i..i + n], &mut s.scores[i..i + n]);
            let cross = &s.cross[y * stride + xb..][..n];
            for x in 0..n {
                out[x] = nc(k, sp[x], spp[x], cross[x]);
            }
            let m = out.iter().copied().fold(f32::MIN, f32::max);
            if m > best.score || (m == best.score && i < best.index) {
                let at = out.iter().position(|&v| v == m).unwrap_or(0);
                if m > best.score || i + at < best.index {
                    *best = Best { score: m, index: i + at };
                }
            }
        }
    }
}

/// [`score`] compiled for AVX-512.
///
/// # Safety
/// The CPU must have the features of [`Path::Avx512`].
#[multiversion::target("x86_64+avx2+fma+bmi2+avx512f+avx512bw+avx512vnni")]
unsafe fn score_avx512(s: Scoring<'_>, k: &Consts, blocks: &[u32], best: &mut Best) {
    score(s, k, blocks, best)
}

/// [`score`] compiled for AVX2 and FMA (which it does not fuse).
///
/// # Safety
/// The CPU must have the features of [`Path::Avx2`].
#[multiversion::target("x86_64+avx2+fma+bmi2")]
unsafe fn score_avx2(s: Scoring<'_>, k: &Consts, blocks: &[u32], best: &mut Best) {
    score(s, k, blocks, best)
}
