//! The Moravec interest operator (001 §2.4, 003): a pixel is interesting when its neighbourhood
//! differs from itself shifted in every direction. For each of the four shifts (right, down and
//! the two diagonals) the squared differences are summed over a `k x k` window; the interest is
//! the smallest of the four sums, and the corners are its local maxima above a threshold.
//!
//! The window sums slide (`interest.rs`), and the corners are picked as the interest rows stream
//! past (`peaks.rs`), so the operator never writes a whole-frame map.

mod interest;
mod peaks;
mod peaks_portable;
mod peaks_simd;

use crate::image::{Gray, Rect, VisionError};
use crate::simd::Path;
use interest::{Columns, RowSink, interest_rows};
use peaks::{PeakSink, Peaks};

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
    cols: Columns,
    peaks: Peaks,
    corners: Vec<Corner>,
    map: Vec<u32>,
    /// The instruction-set path, if not [`Path::active`] (tests and benchmarks set it).
    path: Option<Path>,
}

impl Moravec {
    /// Runs on `path` from now on (lowered to the fastest the CPU has): every path finds the
    /// same corners and interest, bit for bit.
    pub fn set_path(&mut self, path: Path) {
        self.path = Some(Path::clamp(path));
    }

    /// The instruction-set path this operator runs.
    pub fn path(&self) -> Path {
        self.path.unwrap_or_else(Path::active)
    }

    /// The corners in `window`, strongest first (ties: top to bottom, left to right).
    pub fn corners(
        &mut self,
        img: &Gray<'_>,
        window: Rect,
        p: &MoravecParams,
    ) -> Result<&[Corner], VisionError> {
        let w = checked(img, window, p)?;
        self.corners.clear();
        let path = self.path();
        self.peaks.start(w.width(), w.height(), (w.x0, w.y0), p.suppress_radius, p.threshold, path);
        let mut sink = PeakSink { peaks: &mut self.peaks, corners: &mut self.corners };
        interest_rows(path, img, w, p.window, &mut self.cols, &mut sink);
        self.peaks.finish(&mut self.corners);
        let order = |a: &Corner, b: &Corner| b.interest.cmp(&a.interest).then((a.y, a.x).cmp(&(b.y, b.x)));
        if self.corners.len() > p.max_corners && p.max_corners > 0 {
            self.corners.select_nth_unstable_by(p.max_corners - 1, order);
        }
        self.corners.truncate(p.max_corners);
        self.corners.sort_unstable_by(order); // a total order: unstable is deterministic, and allocates nothing
        Ok(&self.corners)
    }

    /// The corners the last call to [`Moravec::corners`] found.
    pub fn last_corners(&self) -> &[Corner] {
        &self.corners
    }

    /// The interest of every pixel of `window` (0 where the window does not fit), row-major.
    /// [`Moravec::corners`] does not need it: it streams the rows.
    pub fn interest_map(
        &mut self,
        img: &Gray<'_>,
        window: Rect,
        p: &MoravecParams,
    ) -> Result<&[u32], VisionError> {
        let w = checked(img, window, p)?;
        self.map.resize(w.width() * w.height(), 0);
        let path = self.path();
        let mut sink = MapSink { map: &mut self.map, width: w.width() };
        interest_rows(path, img, w, p.window, &mut self.cols, &mut sink);
        Ok(&self.map)
    }
}

/// The window, if it is inside the image and the parameters make sense.
fn checked(img: &Gray<'_>, window: Rect, p: &MoravecParams) -> Result<Rect, VisionError> {
    let w = window.inside(img.width, img.height)?;
    if p.window.is_multiple_of(2) || !(3..=9).contains(&p.window) {
        return Err(VisionError::BadParameter(format!("Moravec window {} is not odd in 3..=9", p.window)));
    }
    Ok(w)
}

/// Interest rows written into a whole-window map.
struct MapSink<'a> {
    map: &'a mut [u32],
    width: usize,
}

impl RowSink for MapSink<'_> {
    fn row(&mut self, y: usize) -> &mut [u32] {
        &mut self.map[y * self.width..(y + 1) * self.width]
    }

    fn done(&mut self, _y: usize) {}
}

#[cfg(test)]
mod tests {
    use super::interest::SHIFTS;
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
        for k in [3, 5, 7, 9] {
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

    /// The corners by the definition: the strict-first local maxima of `map` (`w` wide, `h` high,
    /// of window `win`), in image coordinates, in scan order.
    fn brute_corners(map: &[u32], w: usize, h: usize, win: Rect, r: usize, t: u32) -> Vec<(usize, usize)> {
        let at = |x: usize, y: usize| map[y * w + x];
        let mut want = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let v = at(x, y);
                let nbrs = (y.saturating_sub(r)..=(y + r).min(h - 1))
                    .flat_map(|j| (x.saturating_sub(r)..=(x + r).min(w - 1)).map(move |i| (i, j)));
                let peak = nbrs.clone().all(|(i, j)| at(i, j) <= v)
                    && !nbrs.filter(|&(i, j)| (j, i) < (y, x)).any(|(i, j)| at(i, j) == v);
                if v >= t.max(1) && peak {
                    want.push((win.x0 + x, win.y0 + y));
                }
            }
        }
        want
    }

    #[test]
    fn corners_match_the_definition_for_radii_windows_plateaus_and_both_code_paths() {
        // Texture, and a coarse checkerboard whose repeats give plateaus of equal interest.
        let texture = GrayBuf::from_fn(83, 61, |x, y| ((x * 37 + y * 91 + x * y * 13) % 251) as u8);
        let boards = GrayBuf::from_fn(83, 61, |x, y| if (x / 10 + y / 10) % 2 == 0 { 200 } else { 30 });
        let mut paths: Vec<(Path, Moravec)> = Path::available()
            .into_iter()
            .map(|path| {
                let mut m = Moravec::default();
                m.set_path(path);
                (path, m)
            })
            .collect();
        for (name, img) in [("texture", &texture), ("checkerboard", &boards)] {
            let v = img.view();
            for win in [v.full(), Rect::new(7, 5, 70, 50), Rect::new(3, 2, 30, 14)] {
                for r in [0, 1, 2, 3, 5] {
                    let p = MoravecParams {
                        window: 5,
                        threshold: 20_000,
                        suppress_radius: r,
                        max_corners: 100_000,
                    };
                    let mut m = Moravec::default();
                    let map = m.interest_map(&v, win, &p).expect("runs").to_vec();
                    let want = brute_corners(&map, win.width(), win.height(), win, r, p.threshold);
                    for (path, op) in &mut paths {
                        assert_eq!(op.interest_map(&v, win, &p).expect("runs"), &map[..], "{path}");
                        let mut got: Vec<(usize, usize)> =
                            op.corners(&v, win, &p).expect("runs").iter().map(|c| (c.x, c.y)).collect();
                        got.sort_by_key(|&(x, y)| (y, x));
                        assert_eq!(got, want, "{name}, window {win}, radius {r}, {path} code");
                    }
                    if name == "checkerboard" && win == v.full() && r == 3 {
                        // The board's crossings repeat, so many corners share one interest, and
                        // ties within a crossing had to be resolved.
                        let mut values: Vec<u32> = want.iter().map(|&(x, y)| map[y * 83 + x]).collect();
                        values.sort_unstable();
                        values.dedup();
                        assert!(
                            want.len() >= 20 && values.len() * 4 <= want.len(),
                            "{} corners, {values:?}",
                            want.len()
                        );
                        let ties = map.iter().filter(|&&u| u >= p.threshold && values.contains(&u)).count();
                        assert!(ties > 2 * want.len(), "plateaus: {ties} pixels share the corners' values");
                    }
                }
            }
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
