//! Activity detection (004 §4.1): where successive frames of a window differ, in both variants
//! of the paper (absolute differences, or votes over a threshold).
//!
//! The motion plane is the sum of the kept frame pairs' difference images, and all that is read
//! of it is its moments (sum, `Σ x v`, `Σ y v`), which are linear in the plane: so each pair's
//! moments are taken once, as its difference is formed, and the plane's are the sum of the kept
//! pairs' (exact integers, so the same as summing the plane itself). A push is one pass over the
//! window: the new row is differenced against the kept one (which it replaces), the differences
//! go into a per-column sum (16-bit, over bands of 257 rows) and a row sum, and `Σ x v` comes from the column sums at the end. The
//! pass is one body compiled for each [`Path`] (the same integers on all).

use std::collections::VecDeque;

use crate::image::{Gray, GrayBuf, Rect, VisionError};
use crate::simd::Path;

/// How differences count in the motion plane (004 §4.1: "two variations").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ActivityVote {
    /// The absolute intensity difference.
    Difference,
    /// One vote for each difference over this threshold, whatever the contrast.
    Threshold(u8),
}

/// Where the motion is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Activity {
    /// Activity-weighted centroid of the window's motion plane.
    pub centroid: [f32; 2],
    /// Mean activity per pixel per frame pair.
    pub strength: f32,
}

/// The moments of one pair's difference image: `Σ v`, `Σ x v`, `Σ y v` (window coordinates).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Moments {
    sum: u64,
    sx: u64,
    sy: u64,
}

/// Activity detection over the last `depth` frames of one window.
#[derive(Debug)]
pub struct ActivityDetector {
    pub vote: ActivityVote,
    depth: usize,
    /// The newest frame's window, once one has been pushed.
    last: Option<GrayBuf>,
    /// The moments of the kept frame pairs, oldest first (at most `depth - 1`).
    pairs: VecDeque<Moments>,
    columns: Vec<u16>,
    path: Option<Path>,
}

impl ActivityDetector {
    pub fn new(vote: ActivityVote, depth: usize) -> Self {
        Self {
            vote,
            depth: depth.max(2),
            last: None,
            pairs: VecDeque::new(),
            columns: Vec::new(),
            path: None,
        }
    }

    /// Runs on `path` from now on (lowered to the fastest the CPU has): every path gives the
    /// same activity, bit for bit.
    pub fn set_path(&mut self, path: Path) {
        self.path = Some(Path::clamp(path));
    }

    /// Adds a frame's `window` (the same size every time) and returns the activity over the frames
    /// kept, once there are two.
    pub fn push(&mut self, img: &Gray<'_>, window: Rect) -> Result<Option<Activity>, VisionError> {
        let w = window.inside(img.width, img.height)?;
        let Some(last) = self.last.as_mut() else {
            self.last = Some(GrayBuf::crop(img, w)?);
            return Ok(None);
        };
        if (last.width, last.height) != (w.width(), w.height()) {
            return Err(VisionError::BadParameter(format!("window {w} changed size between frames")));
        }
        self.columns.clear();
        self.columns.resize(w.width(), 0);
        let pass = Pass { img, window: w, last, columns: &mut self.columns, vote: self.vote };
        let m = match self.path.unwrap_or_else(Path::active) {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the path is one the CPU has (`set_path` and `Path::active` clamp it).
            Path::Avx512 => unsafe { moments_avx512(pass) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Path::Avx2 => unsafe { moments_avx2(pass) },
            _ => moments(pass),
        };
        self.pairs.push_back(m);
        while self.pairs.len() >= self.depth {
            self.pairs.pop_front();
        }
        let total = self.pairs.iter().fold(Moments::default(), |a, m| Moments {
            sum: a.sum + m.sum,
            sx: a.sx + m.sx,
            sy: a.sy + m.sy,
        });
        let (pairs, n) = (self.pairs.len() as f64, (w.width() * w.height()) as f64);
        let sum = total.sum as f64;
        let (sx, sy) = (total.sx as f64 + 0.5 * sum, total.sy as f64 + 0.5 * sum);
        if sum == 0.0 {
            return Ok(Some(Activity { centroid: [f32::NAN; 2], strength: 0.0 }));
        }
        let centroid = [(w.x0 as f64 + sx / sum) as f32, (w.y0 as f64 + sy / sum) as f32];
        Ok(Some(Activity { centroid, strength: (sum / pairs / n) as f32 }))
    }
}

/// One push's pass: the window of `img` against `last` (which it overwrites).
struct Pass<'a, 'b> {
    img: &'a Gray<'b>,
    window: Rect,
    last: &'a mut GrayBuf,
    columns: &'a mut [u16],
    vote: ActivityVote,
}

/// Rows per band: a band's column sums fit a `u16` (255 a pixel).
const BAND: usize = 257;

/// The new pair's moments, with `last` becoming the new frame.
#[inline(always)]
fn moments(p: Pass<'_, '_>) -> Moments {
    let (w, width) = (p.window, p.window.width());
    let mut m = Moments::default();
    let mut rows = (w.y0..w.y1).zip(p.last.data.chunks_exact_mut(width)).peekable();
    while rows.peek().is_some() {
        p.columns.fill(0);
        for (y, old) in rows.by_ref().take(BAND) {
            let new = &p.img.row(y)[w.x0..w.x1];
            // A row's sum stays below 2^32 (255 a pixel).
            let rs = match p.vote {
                ActivityVote::Difference => row(old, new, p.columns, |a, b| a.abs_diff(b)),
                ActivityVote::Threshold(t) => row(old, new, p.columns, |a, b| u8::from(a.abs_diff(b) > t)),
            };
            m.sum += u64::from(rs);
            m.sy += (y - w.y0) as u64 * u64::from(rs);
        }
        m.sx += p.columns.iter().enumerate().map(|(x, &c)| x as u64 * u64::from(c)).sum::<u64>();
    }
    m
}

/// One row: votes of `old` against `new` into `columns`, `new` copied over `old`; the row's sum.
#[inline(always)]
fn row(old: &mut [u8], new: &[u8], columns: &mut [u16], vote: impl Fn(u8, u8) -> u8) -> u32 {
    let mut rs = 0u32;
    for ((o, &n), c) in old.iter_mut().zip(new).zip(columns.iter_mut()) {
        let v = vote(*o, n);
        *c += u16::from(v);
        rs += u32::from(v);
        *o = n;
    }
    rs
}

/// [`moments`] compiled for AVX-512.
///
/// # Safety
/// The CPU must have the features of [`Path::Avx512`].
#[multiversion::target("x86_64+avx2+fma+bmi2+avx512f+avx512bw+avx512vnni")]
unsafe fn moments_avx512(p: Pass<'_, '_>) -> Moments {
    moments(p)
}

/// [`moments`] compiled for AVX2.
///
/// # Safety
/// The CPU must have the features of [`Path::Avx2`].
#[multiversion::target("x86_64+avx2+fma+bmi2")]
unsafe fn moments_avx2(p: Pass<'_, '_>) -> Moments {
    moments(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The definition: the motion plane of the kept frames, summed pixel by pixel.
    fn plane_moments(frames: &[GrayBuf], vote: ActivityVote, at: (usize, usize)) -> Option<Activity> {
        let (first, rest) = frames.split_first()?;
        let (w, n) = (first.width, first.data.len());
        let mut plane = vec![0u64; n];
        for (a, b) in frames.iter().zip(rest) {
            for ((p, &x), &y) in plane.iter_mut().zip(&a.data).zip(&b.data) {
                let d = x.abs_diff(y);
                *p += u64::from(match vote {
                    ActivityVote::Difference => d,
                    ActivityVote::Threshold(t) => u8::from(d > t),
                });
            }
        }
        let sum: u64 = plane.iter().sum();
        let sx: u64 = plane.iter().enumerate().map(|(i, &v)| (i % w) as u64 * v).sum();
        let sy: u64 = plane.iter().enumerate().map(|(i, &v)| (i / w) as u64 * v).sum();
        let (s, fx, fy) = (sum as f64, sx as f64 + 0.5 * sum as f64, sy as f64 + 0.5 * sum as f64);
        if sum == 0 {
            return Some(Activity { centroid: [f32::NAN; 2], strength: 0.0 });
        }
        Some(Activity {
            centroid: [(at.0 as f64 + fx / s) as f32, (at.1 as f64 + fy / s) as f32],
            strength: (s / rest.len() as f64 / n as f64) as f32,
        })
    }

    fn hashed(w: usize, h: usize, seed: usize) -> GrayBuf {
        GrayBuf::from_fn(w, h, |x, y| {
            ((x * 73 + y * 151 + seed * 977) ^ (x * y + seed)).wrapping_mul(2_654_435_761) as u8
        })
    }

    #[test]
    fn every_path_gives_the_plane_moments_on_odd_widths() {
        for (w, h) in [(1, 5), (15, 9), (17, 4), (641, 7), (33, 40)] {
            let frames: Vec<GrayBuf> = (0..7).map(|k| hashed(w + 3, h + 2, k)).collect();
            let win = Rect::new(2, 1, w + 2, h + 1);
            for vote in [ActivityVote::Difference, ActivityVote::Threshold(100)] {
                for path in Path::available() {
                    let mut d = ActivityDetector::new(vote, 4);
                    d.set_path(path);
                    let mut kept: Vec<GrayBuf> = Vec::new();
                    for f in &frames {
                        let got = d.push(&f.view(), win).expect("runs");
                        kept.push(GrayBuf::crop(&f.view(), win).expect("crop"));
                        if kept.len() > 4 {
                            kept.remove(0);
                        }
                        let want =
                            if kept.len() < 2 { None } else { plane_moments(&kept, vote, (win.x0, win.y0)) };
                        assert_eq!(format!("{got:?}"), format!("{want:?}"), "{path}, {w}x{h}, {vote:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_window_that_changes_size_is_an_error() {
        let f = hashed(40, 30, 1);
        let mut d = ActivityDetector::new(ActivityVote::Difference, 3);
        assert_eq!(d.push(&f.view(), Rect::new(0, 0, 20, 20)).expect("runs"), None);
        assert!(matches!(d.push(&f.view(), Rect::new(0, 0, 21, 20)), Err(VisionError::BadParameter(_))));
        assert!(matches!(d.push(&f.view(), Rect::new(30, 0, 50, 20)), Err(VisionError::WindowOutside(..))));
    }
}
