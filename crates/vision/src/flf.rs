//! The fast line finder (001 §2.1, after Burns, Hanson and Riseman; Kahn, Kitchen and Riseman):
//! pixels are grouped by coarsely quantised gradient orientation into edge-support regions
//! (connected components), and one line is fitted to each region with its statistics; lines
//! are then filtered on length, gradient magnitude, dispersion and orientation.
//!
//! Buckets can be tuned (their count and the orientation the first starts at). With
//! `overlap`, a second partition shifted by half a bucket runs too and every pixel votes for
//! the longer of its two regions, so a line that straddles a bucket boundary is not broken
//! (Burns' overlapping partitions).
//!
//! Regions are built from runs of equal bucket along rows joined by union-find, and their
//! moments come from closed forms over each run, so the work is per run, not per pixel.

use crate::flf_pass::{self, Buckets, Pass, SIDE};
use crate::image::{Gray, Rect, VisionError};
use crate::regions::{Moments, Runs, cell_gradient};
use crate::simd::Path;

/// Settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlfParams {
    /// Orientation buckets over 360 degrees of gradient direction (2 to 15).
    pub buckets: u8,
    /// Gradient direction where the first bucket starts (tune a bucket onto an expected line).
    pub offset_deg: f32,
    /// Second partition shifted by half a bucket, pixels voting for their longer region.
    pub overlap: bool,
    /// Gradient magnitude (grey levels per pixel) below which a pixel supports no line.
    pub min_gradient: f32,
    /// Filters on the fitted lines.
    pub min_length: f32,
    pub min_mean_gradient: f32,
    /// Largest spread across the line (standard deviation, pixels).
    pub max_dispersion: f32,
    /// Keep only lines whose direction (0..180 degrees, image x to the right, y down) lies in
    /// this range; `None` keeps all.
    pub orientation_deg: Option<(f32, f32)>,
    /// Adaptive thresholds: the gradient floors are raised to this many times the window's own
    /// noise sigma (`noise::noise_sigma`; the mean-gradient floor too), so that a
    /// noisy camera's speckle does not break the edge-support regions up. 0: fixed floors.
    pub noise_factor: f32,
}

impl Default for FlfParams {
    fn default() -> Self {
        Self {
            buckets: 8,
            offset_deg: 0.0,
            overlap: true,
            min_gradient: 8.0,
            min_length: 10.0,
            min_mean_gradient: 12.0,
            max_dispersion: 2.0,
            orientation_deg: None,
            // Noise alone passes 3.5 sigma in 0.2 % of the cells (a Rayleigh magnitude).
            noise_factor: 3.5,
        }
    }
}

/// The fitted line the finder reports (defined with the region moments it comes from).
pub use crate::regions::Line;

/// The line finder with its buffers and its orientation look-up table.
#[derive(Debug, Default)]
pub struct Flf {
    lut: Vec<u8>,
    lut_key: Option<(u8, u32, bool)>,
    labels: Vec<u8>,
    gradients: Vec<i16>,
    runs: [Runs; 2],
    moments: [Vec<Moments>; 2],
    lengths: [Vec<f32>; 2],
    votes: Vec<u32>,
    lines: Vec<Line>,
    path: Option<Path>,
}

impl Flf {
    /// Runs on `path` from now on (lowered to the fastest the CPU has): every path finds the
    /// same lines, bit for bit.
    pub fn set_path(&mut self, path: Path) {
        self.path = Some(Path::clamp(path));
    }

    /// The path the gradient pass and the run extraction take.
    pub fn path(&self) -> Path {
        self.path.unwrap_or_else(Path::active)
    }

    /// The lines in `window`, longest first.
    pub fn lines(&mut self, img: &Gray<'_>, window: Rect, p: &FlfParams) -> Result<&[Line], VisionError> {
        let w = window.inside(img.width, img.height)?;
        let usable = (2..=15).contains(&p.buckets) && p.offset_deg.is_finite() && p.min_gradient.is_finite();
        if !usable || p.min_gradient < 0.0 {
            return Err(VisionError::BadParameter(format!(
                "FLF buckets {} (2..=15), offset, gradient",
                p.buckets
            )));
        }
        self.lines.clear();
        if w.width() < 2 || w.height() < 2 {
            return Ok(&self.lines);
        }
        let adapted;
        let p = if p.noise_factor > 0.0 {
            let floor = p.noise_factor * crate::noise::noise_sigma(img, w);
            adapted = FlfParams {
                min_gradient: p.min_gradient.max(floor).round(),
                min_mean_gradient: p.min_mean_gradient.max(floor),
                ..*p
            };
            &adapted
        } else {
            p
        };
        self.build_lut(p);
        self.label(img, w, p);
        let (ww, wh) = (w.width() - 1, w.height() - 1);
        let partitions = if p.overlap { 2 } else { 1 };
        let path = self.path();
        for k in 0..partitions {
            self.runs[k].build(&self.labels, ww, wh, k == 1, path);
            // Cell (x, y) lies between pixels x, x + 1 and rows y, y + 1: centred on the pixel
            // corner (w.x0 + x + 1, w.y0 + y + 1).
            let origin = [w.x0 as f64 + 1.0, w.y0 as f64 + 1.0];
            self.runs[k].moments(origin, &mut self.moments[k], |x, y| cell_gradient(img, w.x0 + x, w.y0 + y));
            self.lengths[k].clear();
            self.lengths[k].extend(self.moments[k].iter().map(|m| m.line().map_or(0.0, |l| l.length)));
        }
        // Every region starts with all its pixels' votes; with overlap, each pixel covered by
        // regions of both partitions takes its vote from the shorter one.
        self.votes.clear();
        for k in 0..partitions {
            self.votes.extend(self.moments[k].iter().map(|m| m.n as u32));
        }
        if p.overlap {
            let n0 = self.moments[0].len();
            let (lengths, votes) = (&self.lengths, &mut self.votes);
            Runs::overlaps(&self.runs[0], &self.runs[1], |a, b, len| {
                if lengths[0][a] >= lengths[1][b] {
                    votes[n0 + b] -= len;
                } else {
                    votes[a] -= len;
                }
            });
        }
        let mut idx = 0;
        for k in 0..partitions {
            for m in &self.moments[k] {
                let votes = self.votes[idx];
                idx += 1;
                if 2 * votes as usize <= m.n as usize {
                    continue;
                }
                if let Some(l) = m.line().filter(|l| keep(l, p)) {
                    self.lines.push(l);
                }
            }
        }
        // A total order (ties broken by position), unstable: sorting allocates nothing.
        self.lines.sort_unstable_by(|a, b| {
            b.length
                .total_cmp(&a.length)
                .then(a.from[1].total_cmp(&b.from[1]))
                .then(a.from[0].total_cmp(&b.from[0]))
        });
        Ok(&self.lines)
    }

    /// Readies the table of every gradient's bucket byte (both partitions in one byte) for
    /// `p`'s buckets: emptied when they change, filled by the gradient pass as it meets each
    /// gradient. The pass looks it up for strong cells only, so it does not depend on the
    /// strength floor (which follows the image's noise from frame to frame), and only the
    /// gradients a camera produces cost an `atan2` (a whole table is 261 121 of them).
    fn build_lut(&mut self, p: &FlfParams) {
        let key = (p.buckets, p.offset_deg.to_bits(), p.overlap);
        if self.lut_key == Some(key) {
            return;
        }
        self.lut_key = Some(key);
        self.lut.clear();
        self.lut.resize(SIDE * SIDE, flf_pass::UNSEEN);
    }

    /// The bucket byte of each 2x2 cell of the window: `(width - 1) x (height - 1)`.
    fn label(&mut self, img: &Gray<'_>, w: Rect, p: &FlfParams) {
        let (ww, wh) = (w.width() - 1, w.height() - 1);
        self.labels.clear();
        self.labels.resize(ww * wh, 0);
        self.gradients.clear();
        self.gradients.resize(2 * ww, 0);
        let strong = (p.min_gradient * p.min_gradient).max(1.0).ceil() as i32;
        let path = self.path();
        let buckets = Buckets { count: p.buckets, offset_deg: p.offset_deg, overlap: p.overlap };
        let (lut, labels, g) = (&mut self.lut, &mut self.labels, &mut self.gradients);
        let pass = Pass { img, window: w, strong, buckets, lut, labels, g };
        flf_pass::label(path, pass);
    }
}

fn keep(l: &Line, p: &FlfParams) -> bool {
    let in_range = |(lo, hi): (f32, f32)| {
        let o = l.orientation_deg;
        if lo <= hi { (lo..=hi).contains(&o) } else { o >= lo || o <= hi }
    };
    l.length >= p.min_length
        && l.mean_gradient >= p.min_mean_gradient
        && l.dispersion <= p.max_dispersion
        && p.orientation_deg.is_none_or(in_range)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::GrayBuf;

    /// A dark ground with a bright convex region where `inside(x, y)`, anti-aliased by 4x4
    /// supersampling so slanted edges are clean.
    fn shape(w: usize, h: usize, inside: impl Fn(f32, f32) -> bool) -> GrayBuf {
        GrayBuf::from_fn(w, h, |x, y| {
            let n = (0..16)
                .filter(|k| {
                    inside(x as f32 + (k % 4) as f32 / 4.0 + 0.125, y as f32 + (k / 4) as f32 / 4.0 + 0.125)
                })
                .count();
            (40 + n * 160 / 16) as u8
        })
    }

    #[test]
    fn the_sides_of_a_rectangle_come_out_with_their_endpoints() {
        let img = shape(120, 100, |x, y| (30.0..90.0).contains(&x) && (20.0..80.0).contains(&y));
        let mut f = Flf::default();
        let lines = f.lines(&img.view(), img.view().full(), &FlfParams::default()).expect("runs").to_vec();
        assert_eq!(lines.len(), 4, "{lines:#?}");
        // The left side: the edge between columns 29 and 30 is x = 30, from y = 20 to 80.
        let left = lines.iter().find(|l| l.from[0] < 35.0 && l.to[0] < 35.0).expect("left side");
        assert!((left.orientation_deg - 90.0).abs() < 1.0, "{left:?}");
        assert!((left.from[0] - 30.0).abs() < 0.6 && (left.to[0] - 30.0).abs() < 0.6, "{left:?}");
        let (top, bottom) = (left.from[1].min(left.to[1]), left.from[1].max(left.to[1]));
        assert!((top - 20.0).abs() < 2.0 && (bottom - 80.0).abs() < 2.0, "{left:?}");
        assert!(left.mean_gradient > 60.0 && left.dispersion < 1.0, "{left:?}");
    }

    #[test]
    fn overlapping_partitions_keep_a_line_on_a_bucket_boundary_whole() {
        // An edge whose gradient points at 45 degrees, exactly on a boundary of 8 buckets from 0;
        // a little sensor noise puts its pixels on either side of the boundary.
        let clean = shape(100, 100, |x, y| x + y > 100.0);
        let noise = |i: usize| ((i.wrapping_mul(2_654_435_761) >> 13) % 9) as u8;
        let img =
            GrayBuf { data: clean.data.iter().enumerate().map(|(i, v)| v + noise(i)).collect(), ..clean };
        let mut f = Flf::default();
        let base = FlfParams { min_length: 5.0, ..FlfParams::default() };
        let split = f
            .lines(&img.view(), img.view().full(), &FlfParams { overlap: false, ..base })
            .expect("runs")
            .to_vec();
        let whole = f.lines(&img.view(), img.view().full(), &base).expect("runs").to_vec();
        let longest = |l: &[Line]| l.first().map_or(0.0, |l| l.length);
        assert!(longest(&whole) > 120.0, "{whole:#?}");
        assert!((whole[0].orientation_deg - 135.0).abs() < 1.0, "{:?}", whole[0]);
        assert!(longest(&split) < 0.5 * longest(&whole), "{} vs {}", longest(&split), longest(&whole));
    }

    #[test]
    fn windows_and_filters_choose_the_lines() {
        let img = shape(120, 100, |x, y| (30.0..90.0).contains(&x) && (20.0..80.0).contains(&y));
        let mut f = Flf::default();
        // A window round the right side only.
        let right =
            f.lines(&img.view(), Rect::new(80, 10, 100, 90), &FlfParams::default()).expect("runs").to_vec();
        assert_eq!(right.len(), 1, "{right:#?}");
        assert!((right[0].from[0] - 90.0).abs() < 0.6, "{:?}", right[0]);
        // Horizontal lines only.
        let p = FlfParams { orientation_deg: Some((170.0, 10.0)), ..FlfParams::default() };
        let flat = f.lines(&img.view(), img.view().full(), &p).expect("runs").to_vec();
        assert_eq!(flat.len(), 2, "{flat:#?}");
        assert!(flat.iter().all(|l| l.orientation_deg < 1.0 || l.orientation_deg > 179.0));
        // Too weak an edge for the gradient filter.
        let faint = shape(60, 60, |x, _| x > 30.0);
        let faint = GrayBuf { data: faint.data.iter().map(|v| 100 + v / 32).collect(), ..faint };
        assert!(f.lines(&faint.view(), faint.view().full(), &FlfParams::default()).expect("runs").is_empty());
        let bad = FlfParams { buckets: 1, ..FlfParams::default() };
        assert!(matches!(f.lines(&img.view(), img.view().full(), &bad), Err(VisionError::BadParameter(_))));
    }

    #[test]
    fn a_finder_reused_over_floors_and_buckets_finds_what_a_fresh_one_does() {
        // The orientation table is filled as gradients come and kept while the buckets stay:
        // a finder that has seen other floors and buckets must find exactly the same lines.
        let disc = shape(160, 120, |x, y| (x - 80.0).hypot(y - 60.0) < 40.0);
        let square = shape(160, 120, |x, y| (x - y).abs() < 30.0 && x + y > 60.0 && x + y < 220.0);
        let p = |buckets, offset_deg, min_gradient, overlap| FlfParams {
            buckets,
            offset_deg,
            min_gradient,
            overlap,
            noise_factor: 0.0,
            min_length: 4.0,
            ..FlfParams::default()
        };
        let runs = [
            (&disc, p(8, 0.0, 8.0, true)),
            (&square, p(8, 0.0, 20.0, true)),
            (&disc, p(8, 0.0, 2.0, true)),
            (&square, p(6, 10.0, 8.0, false)),
            (&disc, p(15, 3.0, 1.0, true)),
            (&disc, p(8, 0.0, 8.0, true)),
        ];
        let mut reused = Flf::default();
        let mut total = 0;
        for (img, p) in runs {
            let (g, full) = (img.view(), img.view().full());
            let again = reused.lines(&g, full, &p).expect("runs").to_vec();
            assert_eq!(again, Flf::default().lines(&g, full, &p).expect("runs"), "{p:?}");
            total += again.len();
        }
        assert!(total > 20, "the images give lines: {total}");
    }
}
