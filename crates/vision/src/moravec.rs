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
    bufs: Buffers,
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

    /// The corners the last call to [`Moravec::corners`] found.
    pub fn last_corners(&self) -> &[Corner] {
        &self.corners
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
        // Centres whose window and shifted window stay inside: a margin of half + 1.
        let m = p.window / 2 + 1;
        if ww <= 2 * m || wh <= 2 * m {
            self.interest.clear();
            self.interest.resize(ww * wh, 0);
            return Ok(&self.interest);
        }
        // Every centre is written below; only the margins need zeros.
        self.interest.resize(ww * wh, 0);
        let (top, bottom) = (m, wh - m);
        self.interest[..top * ww].fill(0);
        self.interest[bottom * ww..].fill(0);
        for row in self.interest[top * ww..bottom * ww].chunks_exact_mut(ww) {
            row[..m].fill(0);
            row[ww - m..].fill(0);
        }
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512bw") {
            // SAFETY: the CPU has AVX-512 F and BW.
            unsafe { interest_avx512(img, w, p.window, &mut self.bufs, &mut self.interest) };
            return Ok(&self.interest);
        }
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            unsafe { interest_avx2(img, w, p.window, &mut self.bufs, &mut self.interest) };
            return Ok(&self.interest);
        }
        interest(img, w, p.window, &mut self.bufs, &mut self.interest);
        Ok(&self.interest)
    }

    /// Local maxima: a pixel at or above the threshold with no larger interest within
    /// `suppress_radius` (a square), and, on a plateau, the first in scan order. Most pixels
    /// fall below the threshold, so candidates are found a block at a time and only they are
    /// compared with their neighbours.
    fn suppress(&mut self, w: Rect, p: &MoravecParams) {
        self.corners.clear();
        let (ww, wh, r) = (self.width, w.height(), p.suppress_radius);
        let threshold = p.threshold.max(1);
        let map = &self.interest;
        for y in 0..wh {
            let row = &map[y * ww..(y + 1) * ww];
            let (ys, ye) = (y.saturating_sub(r), (y + r).min(wh - 1));
            for (b, block) in row.chunks(16).enumerate() {
                if block.iter().fold(0, |m, &v| m.max(v)) < threshold {
                    continue;
                }
                for (i, &v) in block.iter().enumerate() {
                    let x = b * 16 + i;
                    if v < threshold {
                        continue;
                    }
                    // Most candidates are on the slope of a peak: a larger neighbour next door
                    // rules them out before the whole neighbourhood is read.
                    let next_door = |j: usize, i: usize| map[j * ww + i] > v;
                    if (x > 0 && next_door(y, x - 1))
                        || (x + 1 < ww && next_door(y, x + 1))
                        || (y > 0 && next_door(y - 1, x))
                        || (y + 1 < wh && next_door(y + 1, x))
                    {
                        continue;
                    }
                    let (xs, xe) = (x.saturating_sub(r), (x + r).min(ww - 1));
                    let peak = (ys..=ye).all(|j| {
                        let nb = &map[j * ww + xs..=j * ww + xe];
                        match j.cmp(&y) {
                            std::cmp::Ordering::Less => nb.iter().all(|&u| u < v),
                            std::cmp::Ordering::Greater => nb.iter().all(|&u| u <= v),
                            std::cmp::Ordering::Equal => {
                                nb[..x - xs].iter().all(|&u| u < v)
                                    && nb[x - xs + 1..].iter().all(|&u| u <= v)
                            }
                        }
                    });
                    if peak {
                        self.corners.push(Corner { x: w.x0 + x, y: w.y0 + y, interest: v });
                    }
                }
            }
        }
        let order = |a: &Corner, b: &Corner| b.interest.cmp(&a.interest).then((a.y, a.x).cmp(&(b.y, b.x)));
        if self.corners.len() > p.max_corners && p.max_corners > 0 {
            self.corners.select_nth_unstable_by(p.max_corners - 1, order);
        }
        self.corners.truncate(p.max_corners);
        self.corners.sort_unstable_by(order); // a total order: unstable is deterministic, and allocates nothing
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw")]
unsafe fn interest_avx512(img: &Gray<'_>, w: Rect, k: usize, bufs: &mut Buffers, out: &mut [u32]) {
    interest(img, w, k, bufs, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn interest_avx2(img: &Gray<'_>, w: Rect, k: usize, bufs: &mut Buffers, out: &mut [u32]) {
    interest(img, w, k, bufs, out)
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

/// `(p - q)²`: at most 255², which fits 16 bits, so it is formed in 16-bit lanes.
#[inline(always)]
fn sq(p: u8, q: u8) -> u32 {
    let d = i16::from(p) - i16::from(q);
    u32::from(d.wrapping_mul(d) as u16)
}

/// The `k`-wide horizontal sums of one image row's squared differences for one shift:
/// `out[x] = Σ_j D(x + j)`, with `d` as scratch for the differences.
#[inline(always)]
fn row_sums(
    img: &Gray<'_>,
    y: usize,
    x0: usize,
    shift: (isize, isize),
    k: usize,
    d: &mut [u32],
    out: &mut [u32],
) {
    let (a, b) = shifted(img, y, x0, d.len(), shift);
    for ((o, &p), &q) in d.iter_mut().zip(a).zip(b) {
        *o = sq(p, q);
    }
    let m = out.len();
    match k {
        3 => window_sum::<3>(d, out),
        5 => window_sum::<5>(d, out),
        7 => window_sum::<7>(d, out),
        _ => {
            out.copy_from_slice(&d[..m]);
            for j in 1..k {
                for (o, &v) in out.iter_mut().zip(&d[j..j + m]) {
                    *o += v;
                }
            }
        }
    }
}

/// `out[x] = d[x] + … + d[x + K - 1]` in one pass (K shifted slices, which vectorises).
#[inline(always)]
fn window_sum<const K: usize>(d: &[u32], out: &mut [u32]) {
    let m = out.len();
    let taps: [&[u32]; K] = std::array::from_fn(|j| &d[j..j + m]);
    for (x, o) in out.iter_mut().enumerate() {
        let mut s = 0u32;
        for t in &taps {
            s += t[x];
        }
        *o = s;
    }
}

/// Interest of every centre of `w`: per shift, each row's horizontal window sums are made once
/// (kept in a ring of `k + 1` rows), and a column sum per centre adds the row entering the
/// window and takes the row leaving it.
#[inline(always)]
fn interest(img: &Gray<'_>, w: Rect, k: usize, bufs: &mut Buffers, out: &mut [u32]) {
    let (ww, wh, h) = (w.width(), w.height(), k / 2);
    // Columns whose shifted pixels stay in the window: 1 .. ww - 1 (the left and right shifts).
    let (cx0, n) = (1, ww - 2);
    let m = n - 2 * h;
    let top = 1; // first window row (row 0 is needed by the up-right shift)
    let slots = k + 1;
    bufs.ring.clear();
    bufs.ring.resize(SHIFTS.len() * slots * m, 0);
    bufs.cols.clear();
    bufs.cols.resize(SHIFTS.len() * m, 0);
    bufs.diffs.clear();
    bufs.diffs.resize(n, 0);
    let Buffers { ring, cols, diffs } = bufs;
    let slot = |d: usize, r: usize| (d * slots + r % slots) * m;
    for (d, &shift) in SHIFTS.iter().enumerate() {
        for r in top..top + k {
            let at = slot(d, r);
            row_sums(img, w.y0 + r, w.x0 + cx0, shift, k, diffs, &mut ring[at..at + m]);
            for (c, &v) in cols[d * m..(d + 1) * m].iter_mut().zip(&ring[at..at + m]) {
                *c += v;
            }
        }
    }
    // Output row `y` is the window's centre row: rows `y - h ..= y + h`.
    for y in top + h..wh - 1 - h {
        let dst = &mut out[y * ww + cx0 + h..y * ww + cx0 + h + m];
        let (c0, rest) = cols.split_at_mut(m);
        let (c1, rest) = rest.split_at_mut(m);
        let (c2, c3) = rest.split_at_mut(m);
        if y == top + h {
            for ((((o, &a), &b), &c), &e) in dst.iter_mut().zip(&*c0).zip(&*c1).zip(&*c2).zip(&*c3) {
                *o = a.min(b).min(c).min(e);
            }
            continue;
        }
        for (d, &shift) in SHIFTS.iter().enumerate() {
            let enter = slot(d, y + h);
            row_sums(img, w.y0 + y + h, w.x0 + cx0, shift, k, diffs, &mut ring[enter..enter + m]);
        }
        // One pass: each shift's column sums gain the entering row and lose the leaving one,
        // and the interest is their minimum.
        let rows = |d: usize| {
            let (e, l) = (slot(d, y + h), slot(d, y - h - 1));
            (&ring[e..e + m], &ring[l..l + m])
        };
        let ((n0, o0), (n1, o1), (n2, o2), (n3, o3)) = (rows(0), rows(1), rows(2), rows(3));
        for x in 0..m {
            let a = c0[x].wrapping_add(n0[x]).wrapping_sub(o0[x]);
            let b = c1[x].wrapping_add(n1[x]).wrapping_sub(o1[x]);
            let c = c2[x].wrapping_add(n2[x]).wrapping_sub(o2[x]);
            let e = c3[x].wrapping_add(n3[x]).wrapping_sub(o3[x]);
            (c0[x], c1[x], c2[x], c3[x]) = (a, b, c, e);
            dst[x] = a.min(b).min(c).min(e);
        }
    }
}

/// Scratch of [`interest`].
#[derive(Debug, Default)]
struct Buffers {
    ring: Vec<u32>,
    cols: Vec<u32>,
    diffs: Vec<u32>,
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
    fn corners_are_exactly_the_strict_local_maxima() {
        let img = GrayBuf::from_fn(90, 70, |x, y| ((x * 37 + y * 91 + x * y * 13) % 251) as u8);
        let p = MoravecParams { window: 5, threshold: 50_000, suppress_radius: 3, max_corners: 100_000 };
        let mut m = Moravec::default();
        let map = m.interest_map(&img.view(), img.view().full(), &p).expect("runs").to_vec();
        let at = |x: usize, y: usize| map[y * 90 + x];
        let mut want = Vec::new();
        for y in 0..70 {
            for x in 0..90 {
                let v = at(x, y);
                let r = 3usize;
                let nbrs = (y.saturating_sub(r)..=(y + r).min(69))
                    .flat_map(|j| (x.saturating_sub(r)..=(x + r).min(89)).map(move |i| (i, j)));
                let peak = nbrs.clone().all(|(i, j)| at(i, j) <= v)
                    && !nbrs.filter(|&(i, j)| (j, i) < (y, x)).any(|(i, j)| at(i, j) == v);
                if v >= p.threshold && peak {
                    want.push((x, y));
                }
            }
        }
        let mut got: Vec<(usize, usize)> =
            m.corners(&img.view(), img.view().full(), &p).expect("runs").iter().map(|c| (c.x, c.y)).collect();
        got.sort_by_key(|&(x, y)| (y, x));
        assert!(want.len() > 20, "a textured image has many corners: {}", want.len());
        assert_eq!(got, want);
        // The strongest come first, and the cap keeps the strongest.
        let capped =
            m.corners(&img.view(), img.view().full(), &MoravecParams { max_corners: 5, ..p }).expect("runs");
        let top: Vec<u32> = capped.iter().map(|c| c.interest).collect();
        let mut all: Vec<u32> = want.iter().map(|&(x, y)| at(x, y)).collect();
        all.sort_unstable_by(|a, b| b.cmp(a));
        assert_eq!(top, all[..5]);
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
