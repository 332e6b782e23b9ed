//! Reflectance-normalised correlation (000 §5.4). Patch and template are each divided by their
//! own sum, which cancels a constant illumination, and compared by
//! `NC = 2 ΣRP·RT / (ΣRP² + ΣRT²)`, 1 for a patch proportional to the template.
//!
//! With `S_P = ΣP`, `S_T = ΣT` that is `NC = 2 ΣPT S_P S_T / (ΣP² S_T² + ΣT² S_P²)`: only ΣPT
//! needs the template; `S_P` and `ΣP²` come from integral images. ΣPT is computed as
//! `Σ P (T - 128) + 128 S_P`, so the template fits signed bytes and, where the CPU has AVX-512
//! VNNI, sixty-four byte products go into one instruction (`cross.rs`, with an AVX2 and a
//! portable form of the same sums). The patch sums and scores are one body compiled for each
//! [`Path`](crate::simd::Path) (`nc_pass.rs`); [`Correlator::best`] leaves out the blocks of
//! placements whose score bound shows they cannot hold the best.

use crate::cross::{BLOCK_X, BLOCK_Y, Packed, cross, cross_one};
use crate::image::{Gray, GrayBuf, Rect, VisionError};
use crate::nc_pass::{Best, Consts, Scoring, Sums, Window, may_reach, nc, score_blocks};
use crate::simd::Path;

/// Largest template side: keeps `Σ P (T - 128)` inside an `i32`.
pub const MAX_TEMPLATE: usize = 128;

/// A template prepared for correlation.
#[derive(Debug, Clone)]
pub struct Template {
    pub width: usize,
    pub height: usize,
    sum: f64,
    sum_sq: f64,
    /// `T - 128` as signed bytes, packed for the cross-sum kernels.
    packed: Packed,
}

impl Template {
    pub fn new(t: &GrayBuf) -> Result<Self, VisionError> {
        let mut out = Self { width: 0, height: 0, sum: 0.0, sum_sq: 0.0, packed: Packed::default() };
        out.set(t)?;
        Ok(out)
    }

    /// Prepares `t` in place of the current template, reusing its memory.
    pub fn set(&mut self, t: &GrayBuf) -> Result<(), VisionError> {
        let (w, h) = (t.width, t.height);
        if w == 0 || h == 0 || t.data.len() < w * h {
            return Err(VisionError::EmptyTemplate);
        }
        if w > MAX_TEMPLATE || h > MAX_TEMPLATE {
            return Err(VisionError::BadParameter(format!(
                "template {w}x{h} over {MAX_TEMPLATE} pixels a side"
            )));
        }
        let sum: f64 = t.data.iter().map(|&v| f64::from(v)).sum();
        if sum == 0.0 {
            return Err(VisionError::BadParameter("an all-black template has no reflectance pattern".into()));
        }
        self.packed.set(&t.data, w, h);
        self.sum_sq = t.data.iter().map(|&v| f64::from(v) * f64::from(v)).sum();
        (self.width, self.height, self.sum) = (w, h, sum);
        Ok(())
    }
}

/// The best placement of a template.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Match {
    /// Top-left corner of the best placement, in image pixels.
    pub x: usize,
    pub y: usize,
    /// Centre of the matched template in image coordinates (pixel centres at +0.5), refined to
    /// a fraction of a pixel by a parabola through the neighbouring scores.
    pub centre: [f32; 2],
    pub score: f32,
}

/// Reusable buffers: correlating a frame allocates nothing once they have grown.
#[derive(Debug, Default)]
pub struct Correlator {
    pad: Vec<u8>,
    pad_width: usize,
    sums: Sums,
    cross: Vec<i32>,
    scores: Vec<f32>,
    blocks: Vec<u32>,
    nx: usize,
    ny: usize,
    /// The instruction-set path, if not [`Path::active`] (tests and benchmarks set it).
    path: Option<Path>,
}

/// Blocks whose cross-sums are taken at once by [`Correlator::best`] before the bound is
/// raised to the best score found.
const BATCH: usize = 64;

impl Correlator {
    /// Runs on `path` from now on (lowered to the fastest the CPU has): every path gives the
    /// same scores, bit for bit.
    pub fn set_path(&mut self, path: Path) {
        self.path = Some(Path::clamp(path));
    }

    /// The instruction-set path this correlator runs.
    pub fn path(&self) -> Path {
        self.path.unwrap_or_else(Path::active)
    }

    /// Scores every placement of `t` whose pixels all lie in `window`: row-major, `nx x ny`
    /// (see [`Correlator::placements`]), the top-left placement first.
    pub fn correlate(&mut self, img: &Gray<'_>, window: Rect, t: &Template) -> Result<&[f32], VisionError> {
        let k = self.prepare(img, window, t)?;
        self.blocks.clear();
        self.blocks.extend(0..self.sums.bound.len() as u32);
        let mut best = Best::default();
        self.run(t, &k, &mut best);
        Ok(&self.scores[..self.nx * self.ny])
    }

    /// Placements per row and rows of placements of the last correlation.
    pub fn placements(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// The best placement of `t` in `window`: the first (row-major) of the highest scores of
    /// [`Correlator::correlate`], and the same match, bit for bit. Blocks of placements whose
    /// score bound (`nc_pass.rs`) is below a score already found are not correlated: the block
    /// with the highest bound first, then the others in order, a batch at a time.
    pub fn best(&mut self, img: &Gray<'_>, window: Rect, t: &Template) -> Result<Match, VisionError> {
        self.best_at(img, window, t, (0, 0))
    }

    /// [`Correlator::best`] in an image whose pixel `(0, 0)` is pixel `origin` of the frame the
    /// match is reported in (a crop of it).
    pub(crate) fn best_at(
        &mut self,
        img: &Gray<'_>,
        window: Rect,
        t: &Template,
        origin: (usize, usize),
    ) -> Result<Match, VisionError> {
        let k = self.prepare(img, window, t)?;
        let (bounds, n) = (&self.sums.bound, self.sums.bound.len());
        let first = (0..n).fold(0, |b, i| if bounds[i] > bounds[b] { i } else { b });
        let mut best = Best::default();
        self.blocks.clear();
        self.blocks.push(first as u32);
        self.run(t, &k, &mut best);
        for start in (0..n).step_by(BATCH) {
            self.blocks.clear();
            let bounds = &self.sums.bound[start..(start + BATCH).min(n)];
            let todo =
                bounds.iter().enumerate().filter(|&(i, &b)| start + i != first && may_reach(b, best.score));
            self.blocks.extend(todo.map(|(i, _)| (start + i) as u32));
            self.run(t, &k, &mut best);
        }
        let (nx, ny) = (self.nx, self.ny);
        let (px, py, score) = (best.index % nx, best.index / nx, best.score);
        let at = |x: usize, y: usize| {
            let i = y * nx + x;
            nc(&k, self.sums.sp[i], self.sums.spp[i], cross_one(&self.pad, self.pad_width, &t.packed, x, y))
        };
        let vertex = |a: f32, b: f32, c: f32| {
            let d = a - 2.0 * b + c;
            if d < 0.0 { (0.5 * (a - c) / d).clamp(-0.5, 0.5) } else { 0.0 }
        };
        let dx = if px > 0 && px + 1 < nx { vertex(at(px - 1, py), score, at(px + 1, py)) } else { 0.0 };
        let dy = if py > 0 && py + 1 < ny { vertex(at(px, py - 1), score, at(px, py + 1)) } else { 0.0 };
        let (x, y) = (origin.0 + window.x0 + px, origin.1 + window.y0 + py);
        let centre = [x as f32 + t.width as f32 / 2.0 + dx, y as f32 + t.height as f32 / 2.0 + dy];
        Ok(Match { x, y, centre, score })
    }

    /// Checks the request, copies the window and takes the patch sums and bounds.
    fn prepare(&mut self, img: &Gray<'_>, window: Rect, t: &Template) -> Result<Consts, VisionError> {
        let w = window.inside(img.width, img.height)?;
        if t.width > w.width() || t.height > w.height() {
            return Err(VisionError::TemplateTooLarge(t.width, t.height, w));
        }
        let (nx, ny) = (w.width() - t.width + 1, w.height() - t.height + 1);
        (self.nx, self.ny) = (nx, ny);
        self.copy_padded(img, w, t);
        // Every block's cross sums are written before they are read: no need to clear.
        let cells = nx.next_multiple_of(BLOCK_X) * ny.next_multiple_of(BLOCK_Y);
        if self.cross.len() < cells {
            self.cross.resize(cells, 0);
        }
        self.scores.resize(nx * ny, 0.0);
        let k = Consts::new(t.sum, t.sum_sq, t.width, t.height);
        let win = Window { pad: &self.pad, pw: self.pad_width, ww: w.width(), nx, ny };
        self.sums.fill(self.path(), &win, &k);
        Ok(k)
    }

    /// Cross sums and scores of `self.blocks`, the best kept in `best`.
    fn run(&mut self, t: &Template, k: &Consts, best: &mut Best) {
        if self.blocks.is_empty() {
            return;
        }
        let (path, nx, ny) = (self.path(), self.nx, self.ny);
        cross(path, &self.pad, self.pad_width, nx, &t.packed, &self.blocks, &mut self.cross);
        let s = Scoring { sums: &self.sums, cross: &self.cross, scores: &mut self.scores, nx, ny };
        score_blocks(path, s, k, &self.blocks, best);
    }

    /// The window's pixels in rows padded with zeros, so that whole blocks can be read past the
    /// last placement.
    fn copy_padded(&mut self, img: &Gray<'_>, w: Rect, t: &Template) {
        let (nx, ny) = (self.nx, self.ny);
        self.pad_width = nx.next_multiple_of(BLOCK_X) + 4 * t.packed.groups + 32;
        let rows = ny.next_multiple_of(BLOCK_Y) + t.height + BLOCK_Y;
        self.pad.clear();
        self.pad.resize(self.pad_width * rows, 0);
        for (i, y) in (w.y0..w.y1).enumerate() {
            self.pad[i * self.pad_width..i * self.pad_width + w.width()]
                .copy_from_slice(&img.row(y)[w.x0..w.x1]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A textured test image: smooth shading plus a pseudo-random pattern.
    fn scene(w: usize, h: usize) -> GrayBuf {
        GrayBuf::from_fn(w, h, |x, y| {
            let n = (x.wrapping_mul(7919) ^ y.wrapping_mul(104_729)).wrapping_mul(2_654_435_761) >> 7;
            (40 + (x + y) / 8 % 60 + n % 120) as u8
        })
    }

    fn bits(v: &[f32]) -> Vec<u32> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// The formula itself, in f64, placement by placement.
    fn reference(img: &Gray<'_>, win: Rect, t: &GrayBuf) -> Vec<f64> {
        let st: f64 = t.data.iter().map(|&v| f64::from(v)).sum();
        let mut out = Vec::new();
        for y in win.y0..=win.y1 - t.height {
            for x in win.x0..=win.x1 - t.width {
                let sp: f64 = (0..t.height)
                    .flat_map(|r| (0..t.width).map(move |c| (r, c)))
                    .map(|(r, c)| f64::from(img.at(x + c, y + r)))
                    .sum();
                let (mut pt, mut pp, mut tt) = (0.0, 0.0, 0.0);
                for r in 0..t.height {
                    for c in 0..t.width {
                        let rp = f64::from(img.at(x + c, y + r)) / sp;
                        let rt = f64::from(t.data[r * t.width + c]) / st;
                        (pt, pp, tt) = (pt + rp * rt, pp + rp * rp, tt + rt * rt);
                    }
                }
                out.push(2.0 * pt / (pp + tt));
            }
        }
        out
    }

    #[test]
    fn scores_match_the_formula_on_every_path() {
        let img = scene(97, 61);
        for (tw, th) in [(16, 16), (7, 5), (13, 9)] {
            let t = GrayBuf::crop(&img.view(), Rect::new(30, 20, 30 + tw, 20 + th)).expect("crop");
            let tmpl = Template::new(&t).expect("template");
            let win = Rect::new(3, 2, 90, 58);
            let want = reference(&img.view(), win, &t);
            let mut c = Correlator::default();
            let got = c.correlate(&img.view(), win, &tmpl).expect("correlates").to_vec();
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(&want) {
                assert!((f64::from(*g) - w).abs() < 1e-4, "{tw}x{th}: {g} vs {w}");
            }
            // Every path the CPU has gives the same cross sums and scores, bit for bit.
            for path in Path::available() {
                let mut other = Correlator::default();
                other.set_path(path);
                let scores = other.correlate(&img.view(), win, &tmpl).expect("correlates");
                assert_eq!(bits(scores), bits(&got), "{path}, {tw}x{th}");
                let (nx, ny) = c.placements();
                let stride = nx.next_multiple_of(BLOCK_X);
                for y in 0..ny {
                    assert_eq!(&other.cross[y * stride..][..nx], &c.cross[y * stride..][..nx], "{path}");
                }
            }
        }
    }

    #[test]
    fn the_peak_is_where_the_template_was_cut_whatever_the_illumination() {
        let img = scene(120, 90);
        let t = GrayBuf::crop(&img.view(), Rect::new(50, 40, 66, 56)).expect("crop");
        // Half the light: reflectance normalisation makes no difference.
        let dim = GrayBuf { data: t.data.iter().map(|v| v / 2).collect(), ..t.clone() };
        let mut c = Correlator::default();
        for tmpl in [&t, &dim] {
            let m = c.best(&img.view(), img.view().full(), &Template::new(tmpl).expect("t")).expect("best");
            assert_eq!((m.x, m.y), (50, 40));
            assert!(m.score > 0.995, "{}", m.score);
            assert!((m.centre[0] - 58.0).abs() <= 0.5 && (m.centre[1] - 48.0).abs() <= 0.5, "{:?}", m.centre);
        }
    }

    #[test]
    fn bad_requests_are_errors() {
        let img = scene(64, 48);
        let t = Template::new(&GrayBuf::from_fn(16, 16, |x, _| x as u8 + 1)).expect("t");
        let mut c = Correlator::default();
        let outside = c.correlate(&img.view(), Rect::new(50, 0, 70, 20), &t).expect_err("outside");
        assert_eq!(outside, VisionError::WindowOutside(Rect::new(50, 0, 70, 20), 64, 48));
        assert!(matches!(
            c.correlate(&img.view(), Rect::new(0, 0, 10, 40), &t),
            Err(VisionError::TemplateTooLarge(..))
        ));
        assert_eq!(Template::new(&GrayBuf::new(0, 0)).expect_err("empty"), VisionError::EmptyTemplate);
        assert!(Template::new(&GrayBuf::new(4, 4)).is_err(), "all black");
    }
}
