//! The Moravec interest operator (001 §2.4, 003): a pixel is interesting when its neighbourhood
//! differs from itself shifted in every direction. For each of the four shifts (right, down and
//! the two diagonals) the squared differences are summed over a `k x k` window; the interest is
//! the smallest of the four sums, and the corners are its local maxima above a threshold.
//!
//! The window sums slide: per direction a row of column sums gains the row entering the window
//! and loses the row leaving it, and each output row is a short horizontal sum of those.

use crate::image::{Gray, Rect, VisionError};

/// The four shifts.
const SHIFTS: [(isize, isize); 4] = [(1, 0), (0, 1), (1, 1), (1, -1)];

/// Settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoravecParams {
    /// Window side (odd, 3 to 9).
    pub window: usize,
    /// Minimum interest (sum of squared grey-level differences) of a corner.
    pub threshold: u32,
    /// A corner must be the largest interest within this many pixels.
    pub suppress_radius: usize,
    /// At most this many corners, strongest first.
    pub max_corners: usize,
}

impl Default for MoravecParams {
    fn default() -> Self {
        Self { window: 5, threshold: 2000, suppress_radius: 3, max_corners: 200 }
    }
}

/// One interesting point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Corner {
    pub x: usize,
    pub y: usize,
    pub interest: u32,
}

/// The operator with its buffers.
#[derive(Debug, Default)]
pub struct Moravec {
    interest: Vec<u32>,
    cols: Vec<u32>,
    row: Vec<u32>,
    row_max: Vec<u32>,
    max: Vec<u32>,
    corners: Vec<Corner>,
    width: usize,
}

impl Moravec {
    /// The corners in `window`, strongest first (ties: top to bottom, left to right).
    pub fn corners(
        &mut self,
        img: &Gray<'_>,
        window: Rect,
        p: &MoravecParams,
    ) -> Result<&[Corner], VisionError> {
        self.interest_map(img, window, p)?;
        self.suppress(window, p);
        Ok(&self.corners)
    }

    /// The interest of every pixel of `window` (0 where the window does not fit), row-major.
    pub fn interest_map(
        &mut self,
        img: &Gray<'_>,
        window: Rect,
        p: &MoravecParams,
    ) -> Result<&[u32], VisionError> {
        let w = window.inside(img.width, img.height)?;
        if p.window.is_multiple_of(2) || !(3..=9).contains(&p.window) {
            return Err(VisionError::BadParameter(format!(
                "Moravec window {} is not odd in 3..=9",
                p.window
            )));
        }
        let (ww, wh) = (w.width(), w.height());
        self.width = ww;
        self.interest.clear();
        self.interest.resize(ww * wh, 0);
        // Centres whose window and shifted window stay inside: a margin of half + 1.
        let m = p.window / 2 + 1;
        if ww <= 2 * m || wh <= 2 * m {
            return Ok(&self.interest);
        }
        self.cols.clear();
        self.cols.resize(SHIFTS.len() * ww, 0);
        self.row.clear();
        self.row.resize(ww, 0);
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            unsafe { interest_avx2(img, w, p.window, &mut self.cols, &mut self.row, &mut self.interest) };
            return Ok(&self.interest);
        }
        interest(img, w, p.window, &mut self.cols, &mut self.row, &mut self.interest);
        Ok(&self.interest)
    }

    /// Local maxima: a pixel at or above the threshold that equals the largest interest within
    /// `suppress_radius` (a separable maximum filter); of equal neighbours only the first counts.
    fn suppress(&mut self, w: Rect, p: &MoravecParams) {
        self.corners.clear();
        let (ww, wh, r) = (self.width, w.height(), p.suppress_radius);
        for v in [&mut self.row_max, &mut self.max] {
            v.clear();
            v.resize(self.interest.len(), 0);
        }
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            unsafe { dilate_avx2(&self.interest, &mut self.row_max, &mut self.max, ww, wh, r) };
        } else {
            dilate(&self.interest, &mut self.row_max, &mut self.max, ww, wh, r);
        }
        #[cfg(not(target_arch = "x86_64"))]
        dilate(&self.interest, &mut self.row_max, &mut self.max, ww, wh, r);
        let threshold = p.threshold.max(1);
        for y in 0..wh {
            let (vals, maxs) = (&self.interest[y * ww..(y + 1) * ww], &self.max[y * ww..(y + 1) * ww]);
            for x in 0..ww {
                let v = vals[x];
                if v < threshold || v != maxs[x] {
                    continue;
                }
                // On a plateau, only the first pixel in scan order within the radius counts.
                let before = |i: usize, j: usize| (j, i) < (y, x) && self.interest[j * ww + i] == v;
                let twin = (y.saturating_sub(r)..=y)
                    .any(|j| (x.saturating_sub(r)..(x + r + 1).min(ww)).any(|i| before(i, j)));
                if !twin {
                    self.corners.push(Corner { x: w.x0 + x, y: w.y0 + y, interest: v });
                }
            }
        }
        self.corners.sort_by(|a, b| b.interest.cmp(&a.interest).then((a.y, a.x).cmp(&(b.y, b.x))));
        self.corners.truncate(p.max_corners);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn dilate_avx2(v: &[u32], row_max: &mut [u32], max: &mut [u32], ww: usize, wh: usize, r: usize) {
    dilate(v, row_max, max, ww, wh, r)
}

/// The largest value within `r` pixels (a square), by rows then columns.
#[inline(always)]
fn dilate(v: &[u32], row_max: &mut [u32], max: &mut [u32], ww: usize, wh: usize, r: usize) {
    dilate_rows(v, row_max, ww, r);
    dilate_cols(row_max, max, ww, wh, r);
}

/// `out[x] = max(v[x - r ..= x + r])` along each row.
#[inline(always)]
fn dilate_rows(v: &[u32], out: &mut [u32], ww: usize, r: usize) {
    for (src, dst) in v.chunks_exact(ww).zip(out.chunks_exact_mut(ww)) {
        dst.copy_from_slice(src);
        for s in 1..=r.min(ww - 1) {
            for (o, &a) in dst[..ww - s].iter_mut().zip(&src[s..]) {
                *o = (*o).max(a);
            }
            for (o, &a) in dst[s..].iter_mut().zip(&src[..ww - s]) {
                *o = (*o).max(a);
            }
        }
    }
}

/// `out[y] = max(v[y - r ..= y + r])` down each column.
#[inline(always)]
fn dilate_cols(v: &[u32], out: &mut [u32], ww: usize, wh: usize, r: usize) {
    for y in 0..wh {
        let dst = &mut out[y * ww..(y + 1) * ww];
        for j in y.saturating_sub(r)..(y + r + 1).min(wh) {
            for (o, &s) in dst.iter_mut().zip(&v[j * ww..(j + 1) * ww]) {
                *o = (*o).max(s);
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn interest_avx2(
    img: &Gray<'_>,
    w: Rect,
    k: usize,
    cols: &mut [u32],
    row: &mut [u32],
    out: &mut [u32],
) {
    interest(img, w, k, cols, row, out)
}

/// The squared differences of image row `y` with itself shifted by `(dx, dy)`, columns
/// `x0 .. x0 + n`.
#[inline(always)]
fn shifted<'a>(
    img: &Gray<'a>,
    y: usize,
    x0: usize,
    n: usize,
    (dx, dy): (isize, isize),
) -> (&'a [u8], &'a [u8]) {
    let a = &img.row(y)[x0..x0 + n];
    let b = &img.row(y.wrapping_add_signed(dy))[x0.wrapping_add_signed(dx)..][..n];
    (a, b)
}

#[inline(always)]
fn sq(p: u8, q: u8) -> u32 {
    let d = i32::from(p) - i32::from(q);
    (d * d) as u32
}

/// Window sums of `k` consecutive column sums, folded into `dst` by minimum (or stored, for
/// the first shift): whole-row passes over shifted slices, which vectorise.
#[inline(always)]
fn fold_min(cols: &[u32], k: usize, sum: &mut [u32], dst: &mut [u32], first: bool) {
    let n = dst.len();
    let sum = &mut sum[..n];
    sum.copy_from_slice(&cols[..n]);
    for j in 1..k {
        for (a, &b) in sum.iter_mut().zip(&cols[j..j + n]) {
            *a += b;
        }
    }
    if first {
        dst.copy_from_slice(sum);
    } else {
        for (o, &v) in dst.iter_mut().zip(sum.iter()) {
            *o = (*o).min(v);
        }
    }
}

#[inline(always)]
fn interest(img: &Gray<'_>, w: Rect, k: usize, cols: &mut [u32], row: &mut [u32], out: &mut [u32]) {
    let (ww, wh, h) = (w.width(), w.height(), k / 2);
    // Columns whose shifted pixels stay in the window: 1 .. ww - 1 (the left and right shifts).
    let (cx0, n) = (1, ww - 2);
    let top = 1; // first window row (row 0 is needed by the up-right shift)
    for (d, &shift) in SHIFTS.iter().enumerate() {
        let c = &mut cols[d * ww..d * ww + n];
        for r in top..top + k {
            let (a, b) = shifted(img, w.y0 + r, w.x0 + cx0, n, shift);
            for ((c, &p), &q) in c.iter_mut().zip(a).zip(b) {
                *c += sq(p, q);
            }
        }
    }
    // Output row `y` is the window's centre row: rows `y - h ..= y + h`.
    for y in top + h..wh - 1 - h {
        let dst = &mut out[y * ww + cx0 + h..y * ww + cx0 + n - h];
        for (d, &shift) in SHIFTS.iter().enumerate() {
            let c = &mut cols[d * ww..d * ww + n];
            if y > top + h {
                let (a, b) = shifted(img, w.y0 + y + h, w.x0 + cx0, n, shift);
                let (e, f) = shifted(img, w.y0 + y - h - 1, w.x0 + cx0, n, shift);
                for ((((c, &p), &q), &r), &s) in c.iter_mut().zip(a).zip(b).zip(e).zip(f) {
                    *c = c.wrapping_add(sq(p, q)).wrapping_sub(sq(r, s));
                }
            }
            fold_min(c, k, row, dst, d == 0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::GrayBuf;

    /// The definition, pixel by pixel.
    fn reference(img: &Gray<'_>, x: usize, y: usize, k: usize) -> u32 {
        let h = k as isize / 2;
        SHIFTS
            .iter()
            .map(|&(dx, dy)| {
                let mut s = 0u32;
                for j in -h..=h {
                    for i in -h..=h {
                        let (px, py) = (x as isize + i, y as isize + j);
                        let d = i32::from(img.at(px as usize, py as usize))
                            - i32::from(img.at((px + dx) as usize, (py + dy) as usize));
                        s += (d * d) as u32;
                    }
                }
                s
            })
            .min()
            .unwrap_or(0)
    }

    #[test]
    fn interest_matches_the_definition_inside_the_margin() {
        let img = GrayBuf::from_fn(40, 30, |x, y| ((x * 37 + y * 91 + x * y * 13) % 251) as u8);
        let mut m = Moravec::default();
        for k in [3, 5, 7] {
            let map = m.interest_map(
                &img.view(),
                img.view().full(),
                &MoravecParams { window: k, ..Default::default() },
            );
            let map = map.expect("runs").to_vec();
            let mg = k / 2 + 1;
            for y in mg..30 - mg {
                for x in mg..40 - mg {
                    assert_eq!(map[y * 40 + x], reference(&img.view(), x, y, k), "k {k} at ({x}, {y})");
                }
            }
        }
    }

    #[test]
    fn corners_of_a_bright_square_are_found_and_its_edges_are_not() {
        // A bright square on a dark ground: edges change along one direction only, corners along all.
        let img =
            GrayBuf::from_fn(
                64,
                64,
                |x, y| if (20..44).contains(&x) && (16..40).contains(&y) { 200 } else { 40 },
            );
        let mut m = Moravec::default();
        let p = MoravecParams { window: 5, threshold: 10_000, suppress_radius: 4, max_corners: 10 };
        let found = m.corners(&img.view(), img.view().full(), &p).expect("runs").to_vec();
        assert_eq!(found.len(), 4, "{found:?}");
        for (cx, cy) in [(20, 16), (43, 16), (20, 39), (43, 39)] {
            assert!(
                // One-sided shifts put the peak up to 2 pixels inside the corner.
                found.iter().any(|c| c.x.abs_diff(cx) <= 2 && c.y.abs_diff(cy) <= 2),
                "no corner near ({cx}, {cy}): {found:?}"
            );
        }
    }

    #[test]
    fn bad_parameters_and_windows_are_errors() {
        let img = GrayBuf::new(32, 32);
        let mut m = Moravec::default();
        let p = MoravecParams { window: 4, ..Default::default() };
        assert!(matches!(m.corners(&img.view(), img.view().full(), &p), Err(VisionError::BadParameter(_))));
        let outside = Rect::new(10, 10, 40, 20);
        assert!(matches!(
            m.corners(&img.view(), outside, &MoravecParams::default()),
            Err(VisionError::WindowOutside(..))
        ));
    }
}
