//! The long-range cues of 004 §4.1 that bring the robot towards a dock: phototropic perception
//! (the brightest region) and activity detection (where successive frames differ, in both
//! variants). The dock itself is recognised by `hough`.

use std::collections::VecDeque;

use crate::frs::{ClassRange, Frs, Region};
use crate::image::{Gray, GrayBuf, Rect, VisionError};

/// Phototropic perception: the largest region within `margin` grey levels of the brightest
/// pixel of `window` (a lamp, a beacon), of at least `min_area` pixels.
pub fn brightest(
    frs: &mut Frs,
    img: &Gray<'_>,
    window: Rect,
    margin: u8,
    min_area: u32,
) -> Result<Option<Region>, VisionError> {
    let w = window.inside(img.width, img.height)?;
    let peak =
        (w.y0..w.y1).map(|y| img.row(y)[w.x0..w.x1].iter().copied().max().unwrap_or(0)).max().unwrap_or(0);
    let ranges = [ClassRange { lo: peak.saturating_sub(margin), hi: 255, class: 1 }];
    Ok(frs.segment(img, w, &ranges, min_area)?.first().copied())
}

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

/// Activity detection over the last `depth` frames of one window.
#[derive(Debug)]
pub struct ActivityDetector {
    pub vote: ActivityVote,
    depth: usize,
    frames: VecDeque<GrayBuf>,
    spare: Vec<GrayBuf>,
    plane: Vec<u32>,
}

impl ActivityDetector {
    pub fn new(vote: ActivityVote, depth: usize) -> Self {
        Self { vote, depth: depth.max(2), frames: VecDeque::new(), spare: Vec::new(), plane: Vec::new() }
    }

    /// Adds a frame's `window` (the same size every time) and returns the activity over the frames
    /// kept, once there are two.
    pub fn push(&mut self, img: &Gray<'_>, window: Rect) -> Result<Option<Activity>, VisionError> {
        let w = window.inside(img.width, img.height)?;
        if self.frames.front().is_some_and(|f| (f.width, f.height) != (w.width(), w.height())) {
            return Err(VisionError::BadParameter(format!("window {w} changed size between frames")));
        }
        let mut buf = self.spare.pop().unwrap_or_default();
        (buf.width, buf.height) = (w.width(), w.height());
        buf.data.clear();
        for y in w.y0..w.y1 {
            buf.data.extend_from_slice(&img.row(y)[w.x0..w.x1]);
        }
        // The motion plane keeps the votes of the pairs in the kept frames: the newest pair is
        // added, and the pair that drops out of the window is taken off.
        let n = w.width() * w.height();
        if self.frames.is_empty() {
            self.plane.clear();
            self.plane.resize(n, 0);
        }
        let vote = self.vote;
        let votes = |a: &GrayBuf, b: &GrayBuf, plane: &mut [u32], add: bool| {
            for ((p, &x), &y) in plane.iter_mut().zip(&a.data).zip(&b.data) {
                let d = x.abs_diff(y);
                let v = match vote {
                    ActivityVote::Difference => u32::from(d),
                    ActivityVote::Threshold(t) => u32::from(d > t),
                };
                *p = if add { *p + v } else { *p - v };
            }
        };
        if let Some(last) = self.frames.back() {
            votes(last, &buf, &mut self.plane, true);
        }
        self.frames.push_back(buf);
        while self.frames.len() > self.depth {
            if let (Some(old), Some(next)) = (self.frames.front(), self.frames.get(1)) {
                votes(old, next, &mut self.plane, false);
            }
            if let Some(old) = self.frames.pop_front() {
                self.spare.push(old);
            }
        }
        if self.frames.len() < 2 {
            return Ok(None);
        }
        let pairs = (self.frames.len() - 1) as f64;
        // Integer moments row by row (exact: at most 255 x 15 votes a pixel).
        let (mut sum, mut sx, mut sy) = (0u64, 0u64, 0u64);
        for (y, row) in self.plane.chunks_exact(w.width()).enumerate() {
            let (rs, rx) = row
                .iter()
                .enumerate()
                .fold((0u64, 0u64), |(s, x), (i, &p)| (s + u64::from(p), x + i as u64 * u64::from(p)));
            (sum, sx, sy) = (sum + rs, sx + rx, sy + y as u64 * rs);
        }
        let (sum, sx, sy) = (sum as f64, sx as f64 + 0.5 * sum as f64, sy as f64 + 0.5 * sum as f64);
        if sum == 0.0 {
            return Ok(Some(Activity { centroid: [f32::NAN; 2], strength: 0.0 }));
        }
        let centroid = [(w.x0 as f64 + sx / sum) as f32, (w.y0 as f64 + sy / sum) as f32];
        Ok(Some(Activity { centroid, strength: (sum / pairs / n as f64) as f32 }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_brightest_region_is_the_lamp() {
        let img = GrayBuf::from_fn(160, 120, |x, y| {
            if (100..112).contains(&x) && (20..28).contains(&y) {
                250
            } else if (10..60).contains(&x) && (60..100).contains(&y) {
                200 // a pale wall, bright but not the lamp
            } else {
                90
            }
        });
        let mut frs = Frs::default();
        let r = brightest(&mut frs, &img.view(), img.view().full(), 20, 10).expect("runs").expect("found");
        assert_eq!((r.area, r.centroid), (96, [106.0, 24.0]));
    }

    #[test]
    fn activity_is_where_things_move_and_the_vote_variant_ignores_low_contrast_flicker() {
        let frame = |k: usize, noise: bool| {
            GrayBuf::from_fn(120, 80, |x, y| {
                let base = 60 + ((x / 8 + y / 8) % 2 * 40) as u8;
                let flicker = if noise { ((x * 31 + y * 17 + k * 7) % 5) as u8 } else { 0 };
                // An arm sweeping right and back between x = 70 and 100, rows 20-40.
                let arm = 70 + (k * 6) % 30;
                if (arm..arm + 10).contains(&x) && (20..40).contains(&y) { 230 } else { base + flicker }
            })
        };
        let mut diff = ActivityDetector::new(ActivityVote::Difference, 4);
        let mut votes = ActivityDetector::new(ActivityVote::Threshold(20), 4);
        let mut last = (None, None);
        for k in 0..6 {
            let f = frame(k, true);
            last = (
                diff.push(&f.view(), f.view().full()).expect("runs"),
                votes.push(&f.view(), f.view().full()).expect("runs"),
            );
        }
        for a in [last.0.expect("activity"), last.1.expect("activity")] {
            assert!((70.0..110.0).contains(&a.centroid[0]) && (20.0..40.0).contains(&a.centroid[1]), "{a:?}");
        }
        // The running plane equals the plane of the frames kept: a fresh detector fed only the
        // last four frames says the same.
        let mut fresh = ActivityDetector::new(ActivityVote::Difference, 4);
        let mut again = None;
        for k in 2..6 {
            let f = frame(k, true);
            again = fresh.push(&f.view(), f.view().full()).expect("runs");
        }
        assert_eq!(again, last.0);
        // Flicker alone: the difference variant sees it, the vote variant does not.
        let mut diff = ActivityDetector::new(ActivityVote::Difference, 3);
        let mut votes = ActivityDetector::new(ActivityVote::Threshold(20), 3);
        for k in 0..3 {
            let f = GrayBuf::from_fn(120, 80, |x, y| 100 + ((x * 31 + y * 17 + k * 7) % 5) as u8);
            last = (
                diff.push(&f.view(), f.view().full()).expect("runs"),
                votes.push(&f.view(), f.view().full()).expect("runs"),
            );
        }
        assert!(last.0.expect("activity").strength > 0.5);
        assert_eq!(last.1.expect("activity").strength, 0.0);
    }
}
