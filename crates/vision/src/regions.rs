//! Connected regions from a class image, as runs: each row's runs of equal class are joined to
//! the touching runs (8-connected) of the row above with union-find. Region moments come from
//! closed forms over each run. Shared by the line finder and the region segmenter.

use crate::image::Gray;
use crate::run_pass::{self, Labels};
use crate::simd::Path;

/// A fitted line with its region's statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    pub from: [f32; 2],
    pub to: [f32; 2],
    pub length: f32,
    /// Direction of the line, 0..180 degrees.
    pub orientation_deg: f32,
    pub mean_gradient: f32,
    /// Standard deviation of the support across the line.
    pub dispersion: f32,
    pub pixels: u32,
}

/// A horizontal run of one class: row `y`, columns `x0 .. x1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Run {
    pub y: u32,
    pub x0: u32,
    pub x1: u32,
    pub class: u8,
    /// Index of its region, `0 .. regions` (after `build`).
    pub region: u32,
}

/// The runs of a class image and the regions they form.
#[derive(Debug, Default)]
pub struct Runs {
    pub runs: Vec<Run>,
    pub regions: usize,
    parent: Vec<u32>,
    index: Vec<u32>,
    /// Each row's first run, then the run count.
    rows: Vec<u32>,
    scratch: Vec<u8>,
}

fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

impl Runs {
    /// Runs of each label's class (its `high` or low nibble; 0: background) over a `w x h` label
    /// image, and their regions; the runs are extracted on `path` (the same on every path).
    pub fn build(&mut self, labels: &[u8], w: usize, h: usize, high: bool, path: Path) {
        let labels = Labels { data: labels, w, h, high };
        run_pass::extract(path, labels, &mut self.scratch, &mut self.runs, &mut self.rows);
        self.parent.clear();
        self.parent.extend(0..self.runs.len() as u32);
        let mut above = 0..0;
        for y in 0..h {
            let (start, end) = (self.rows[y] as usize, self.rows[y + 1] as usize);
            // Join with the touching runs above (diagonal contact counts).
            let mut j = above.start;
            for i in start..end {
                let r = self.runs[i];
                while j < above.end && self.runs[j].x1 < r.x0 {
                    j += 1;
                }
                let mut k = j;
                while k < above.end && self.runs[k].x0 <= r.x1 {
                    if self.runs[k].class == r.class {
                        let (a, b) = (find(&mut self.parent, i as u32), find(&mut self.parent, k as u32));
                        if a != b {
                            self.parent[a.max(b) as usize] = a.min(b);
                        }
                    }
                    k += 1;
                }
            }
            above = start..end;
        }
        self.index.clear();
        self.index.resize(self.runs.len(), u32::MAX);
        self.regions = 0;
        for i in 0..self.runs.len() {
            let root = find(&mut self.parent, i as u32) as usize;
            if self.index[root] == u32::MAX {
                self.index[root] = self.regions as u32;
                self.regions += 1;
            }
            self.runs[i].region = self.index[root];
        }
    }

    /// Moments of every region; `value(x, y)` (run coordinates) is summed over its pixels.
    /// Coordinates are offset by `origin` (where run cell (0, 0) lies in the image).
    pub fn moments(
        &self,
        origin: [f64; 2],
        out: &mut Vec<Moments>,
        mut value: impl FnMut(usize, usize) -> f32,
    ) {
        out.clear();
        out.resize(self.regions, Moments::default());
        for r in &self.runs {
            let m = &mut out[r.region as usize];
            let (a, b) = (f64::from(r.x0) + origin[0], f64::from(r.x1) + origin[0]);
            let y = f64::from(r.y) + origin[1];
            let n = b - a;
            // Σx and Σx² over x = a .. b-1.
            let sx = (a + b - 1.0) * n / 2.0;
            let s2 = |m: f64| m * (m + 1.0) * (2.0 * m + 1.0) / 6.0;
            let sxx = s2(b - 1.0) - s2(a - 1.0);
            m.n += n;
            m.sx += sx;
            m.sy += n * y;
            m.sxx += sxx;
            m.sxy += y * sx;
            m.syy += n * y * y;
            m.class = r.class;
            m.x_min = m.x_min.min(a as f32);
            m.x_max = m.x_max.max((b - 1.0) as f32);
            m.y_min = m.y_min.min(y as f32);
            m.y_max = m.y_max.max(y as f32);
            let row = r.y as usize;
            let (mut v, mut vv) = (0.0f64, 0.0f64);
            for x in r.x0 as usize..r.x1 as usize {
                let p = f64::from(value(x, row));
                v += p;
                vv += p * p;
            }
            m.value += v;
            m.value_sq += vv;
        }
    }

    /// Calls `f(region_in_a, region_in_b, pixels)` for every overlap of a run of `a` with a run
    /// of `b` on the same row (both built over the same image).
    pub fn overlaps(a: &Runs, b: &Runs, mut f: impl FnMut(usize, usize, u32)) {
        let (mut i, mut j) = (0, 0);
        while i < a.runs.len() && j < b.runs.len() {
            let (p, q) = (a.runs[i], b.runs[j]);
            if (p.y, p.x1) <= (q.y, q.x0) {
                i += 1;
                continue;
            }
            if (q.y, q.x1) <= (p.y, p.x0) {
                j += 1;
                continue;
            }
            let len = p.x1.min(q.x1) - p.x0.max(q.x0);
            f(p.region as usize, q.region as usize, len);
            if p.x1 <= q.x1 {
                i += 1;
            } else {
                j += 1;
            }
        }
    }
}

/// Sums over a region's pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moments {
    pub n: f64,
    pub sx: f64,
    pub sy: f64,
    pub sxx: f64,
    pub sxy: f64,
    pub syy: f64,
    /// Sum of the per-pixel value (gradient magnitude, intensity), and of its square.
    pub value: f64,
    pub value_sq: f64,
    pub class: u8,
    pub x_min: f32,
    pub x_max: f32,
    pub y_min: f32,
    pub y_max: f32,
}

impl Default for Moments {
    fn default() -> Self {
        Self {
            n: 0.0,
            sx: 0.0,
            sy: 0.0,
            sxx: 0.0,
            sxy: 0.0,
            syy: 0.0,
            value: 0.0,
            value_sq: 0.0,
            class: 0,
            x_min: f32::MAX,
            x_max: f32::MIN,
            y_min: f32::MAX,
            y_max: f32::MIN,
        }
    }
}

impl Moments {
    pub fn centroid(&self) -> [f64; 2] {
        [self.sx / self.n, self.sy / self.n]
    }

    /// The principal axis as a line: through the centroid, as long as a uniform segment with
    /// the same spread (`sqrt(12 λ1 + 1)`, exact for a row of pixels), `dispersion` the spread
    /// across it; `value` averaged over the pixels as its mean gradient.
    pub fn line(&self) -> Option<Line> {
        if self.n < 2.0 {
            return None;
        }
        let [mx, my] = self.centroid();
        let cxx = self.sxx / self.n - mx * mx;
        let cyy = self.syy / self.n - my * my;
        let cxy = self.sxy / self.n - mx * my;
        let half = (cxx + cyy) / 2.0;
        let root = (((cxx - cyy) / 2.0).powi(2) + cxy * cxy).sqrt();
        let (l1, l2) = (half + root, (half - root).max(0.0));
        let theta = 0.5 * (2.0 * cxy).atan2(cxx - cyy);
        let length = (12.0 * l1 + 1.0).sqrt();
        let (dx, dy) = (theta.cos() * length / 2.0, theta.sin() * length / 2.0);
        Some(Line {
            from: [(mx - dx) as f32, (my - dy) as f32],
            to: [(mx + dx) as f32, (my + dy) as f32],
            length: length as f32,
            orientation_deg: (theta.to_degrees().rem_euclid(180.0)) as f32,
            mean_gradient: (self.value / self.n) as f32,
            dispersion: l2.sqrt() as f32,
            pixels: self.n as u32,
        })
    }
}

/// Gradient magnitude of the 2x2 cell whose top-left pixel is `(x, y)`: the halved sums
/// `gx = (b + d - a - c) / 2`, `gy = (c + d - a - b) / 2` of its pixels `[a b; c d]`, and
/// `sqrt(gx² + gy²)` in `f32`.
#[inline]
pub fn cell_gradient(img: &Gray<'_>, x: usize, y: usize) -> f32 {
    let (r0, r1) = (&img.row(y)[x..x + 2], &img.row(y + 1)[x..x + 2]);
    magnitude(doubled_square([r0[0], r0[1], r1[0], r1[1]]))
}

/// The square sum of a 2x2 cell's doubled gradient components (`b + d - a - c` and
/// `c + d - a - b` for the cell `[a b; c d]`, given in that order): integers, exact.
#[inline]
pub(crate) fn doubled_square(cell: [u8; 4]) -> usize {
    let [a, b, c, d] = cell.map(i32::from);
    let (gx2, gy2) = (b + d - a - c, c + d - a - b);
    (gx2 * gx2 + gy2 * gy2) as usize
}

/// Squared doubled gradients below this (a magnitude under 32 grey levels) take their
/// magnitude from a table.
pub(crate) const TABLED: usize = 4096;

/// The magnitude of a cell whose doubled gradient components square-sum to `s`: `sqrt(s / 4)`
/// in `f32` (the sum of the halved components' squares is `s / 4` exactly), from a table made
/// once below [`TABLED`].
#[inline]
pub(crate) fn magnitude(s: usize) -> f32 {
    static TABLE: std::sync::OnceLock<[f32; TABLED]> = std::sync::OnceLock::new();
    let root = |s: usize| ((s as f32) * 0.25).sqrt();
    match TABLE.get_or_init(|| std::array::from_fn(root)).get(s) {
        Some(&m) => m,
        None => root(s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_cell_s_magnitude_is_the_root_of_its_halved_sums_bit_for_bit() {
        // All the doubled components a 2x2 cell of bytes can have, tabled or not.
        for gx2 in -510i32..=510 {
            for gy2 in -510i32..=510 {
                let (gx, gy) = (gx2 as f32 / 2.0, gy2 as f32 / 2.0);
                let got = magnitude((gx2 * gx2 + gy2 * gy2) as usize);
                assert_eq!(got.to_bits(), (gx * gx + gy * gy).sqrt().to_bits(), "({gx2}, {gy2})");
            }
        }
        // And through an image: the cell [10 40; 200 90] has gx = -40, gy = 120.
        let data = [10u8, 40, 200, 90];
        let img = Gray::new(&data, 2, 2, 2).expect("2x2");
        assert_eq!(cell_gradient(&img, 0, 0), 40f32.hypot(120.0));
    }
}
