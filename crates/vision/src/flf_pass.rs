//! The line finder's gradient pass: the bucket byte of every 2x2 cell of a window. One body
//! compiled for each [`Path`] (the same bytes on all): per row, the gradients of every cell and
//! a strong-or-not mark (a vectorised pass), then the orientation look-up for the strong cells
//! only, weak cells passed over eight at a time (one 64-bit test).

use crate::image::{Gray, Rect};
use crate::simd::Path;

/// Gradient components are halved sums of a 2x2 cell, in -255..=255.
pub(crate) const G: i32 = 255;
/// The side of the look-up table, indexed by `(gy + G) * SIDE + gx + G`.
pub(crate) const SIDE: usize = (2 * G + 1) as usize;

/// A look-up table entry not worked out yet (a bucket byte is never 0: buckets count from 1).
pub(crate) const UNSEEN: u8 = 0;

/// The orientation buckets a gradient is sorted into.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Buckets {
    /// How many over 360 degrees (2 to 15).
    pub count: u8,
    /// Where the first starts.
    pub offset_deg: f32,
    /// A second partition shifted by half a bucket, in the byte's high nibble.
    pub overlap: bool,
}

impl Buckets {
    /// The bucket byte of gradient `(gx, gy)`, not both 0: the bucket from 1 in the low nibble,
    /// the shifted partition's in the high one (0 without overlap).
    #[cold]
    fn byte(self, gx: i32, gy: i32) -> u8 {
        let width = 360.0 / f32::from(self.count);
        let dir = (gy as f32).atan2(gx as f32).to_degrees();
        let bucket = |offset: f32| ((dir - offset).rem_euclid(360.0) / width) as u8 % self.count + 1;
        let a = bucket(self.offset_deg);
        let b = if self.overlap { bucket(self.offset_deg + width / 2.0) } else { 0 };
        a | (b << 4)
    }
}

/// One window's pass: `labels` gets `(width - 1) x (height - 1)` bucket bytes (0: weak), a
/// cell strong where `gx² + gy² >= strong` (at least 1); `lut` is the `SIDE x SIDE` table of
/// bucket bytes, [`UNSEEN`] where not worked out yet (the pass fills in what it meets); `g` is
/// scratch of `2 (width - 1)`.
pub(crate) struct Pass<'a, 'b> {
    pub img: &'a Gray<'b>,
    pub window: Rect,
    pub strong: i32,
    pub buckets: Buckets,
    pub lut: &'a mut [u8],
    pub labels: &'a mut [u8],
    pub g: &'a mut [i16],
}

/// Runs the pass on `path`.
pub(crate) fn label(path: Path, p: Pass<'_, '_>) {
    match path {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the path is one the CPU has (callers clamp it or take `Path::active`).
        Path::Avx512 => unsafe { label_avx512(p) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Path::Avx2 => unsafe { label_avx2(p) },
        _ => label_rows(p),
    }
}

/// The one body.
#[inline(always)]
fn label_rows(p: Pass<'_, '_>) {
    let (w, lut, buckets) = (p.window, p.lut, p.buckets);
    let (ww, wh) = (w.width() - 1, w.height() - 1);
    let (gxs, gys) = p.g.split_at_mut(ww);
    for y in 0..wh {
        let (r0, r1) = (&p.img.row(w.y0 + y)[w.x0..w.x1], &p.img.row(w.y0 + y + 1)[w.x0..w.x1]);
        let out = &mut p.labels[y * ww..(y + 1) * ww];
        let (r0, r1, gxs, gys) = (&r0[..ww + 1], &r1[..ww + 1], &mut gxs[..ww], &mut gys[..ww]);
        for x in 0..ww {
            let (a, b, c, d) =
                (i32::from(r0[x]), i32::from(r0[x + 1]), i32::from(r1[x]), i32::from(r1[x + 1]));
            let gx = (b + d - a - c) / 2;
            let gy = (c + d - a - b) / 2;
            gxs[x] = gx as i16;
            gys[x] = gy as i16;
            out[x] = u8::from(gx * gx + gy * gy >= p.strong);
        }
        let mut x = 0;
        while x < ww {
            if x + 8 <= ww && zero8(&out[x..x + 8]) {
                x += 8;
                continue;
            }
            if out[x] != 0 {
                let (gx, gy) = (i32::from(gxs[x]), i32::from(gys[x]));
                let entry = &mut lut[((gy + G) as usize) * SIDE + (gx + G) as usize];
                if *entry == UNSEEN {
                    *entry = buckets.byte(gx, gy);
                }
                out[x] = *entry;
            }
            x += 1;
        }
    }
}

/// Whether eight bytes are all zero, read as one word.
#[inline(always)]
fn zero8(b: &[u8]) -> bool {
    let mut w = [0u8; 8];
    w.copy_from_slice(&b[..8]);
    u64::from_ne_bytes(w) == 0
}

/// [`label_rows`] compiled for AVX-512.
///
/// # Safety
/// The CPU must have the features of [`Path::Avx512`].
#[multiversion::target("x86_64+avx2+fma+bmi2+avx512f+avx512bw+avx512vnni")]
unsafe fn label_avx512(p: Pass<'_, '_>) {
    label_rows(p)
}

/// [`label_rows`] compiled for AVX2.
///
/// # Safety
/// The CPU must have the features of [`Path::Avx2`].
#[multiversion::target("x86_64+avx2+fma+bmi2")]
unsafe fn label_avx2(p: Pass<'_, '_>) {
    label_rows(p)
}
