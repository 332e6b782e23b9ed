//! Straightforward references for the kernels that build on others: stereo and depth from
//! motion from the reference Moravec operator and correlation, and the constrained Hough
//! transform with one full-resolution accumulator per hypothesis.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use harvey_vision::flf::Line;
use harvey_vision::hough::{DockModel, Hypothesis};
use harvey_vision::{Gray, GrayBuf, Rect};

use crate::reference::{moravec, nc_best};

/// The `max` strongest reference Moravec corners of `win`.
fn strongest(img: &Gray<'_>, win: Rect, threshold: u32, radius: usize, max: usize) -> Vec<(usize, usize)> {
    let mut c = moravec(img, win, 5, threshold, radius);
    c.sort_by_key(|b| std::cmp::Reverse(b.2));
    c.truncate(max);
    c.into_iter().map(|(x, y, _)| (x, y)).collect()
}

fn patch(img: &Gray<'_>, x: usize, y: usize, half: usize) -> GrayBuf {
    GrayBuf::from_fn(2 * half + 1, 2 * half + 1, |i, j| img.at(x + i - half, y + j - half))
}

/// Stereo: each corner's patch correlated over its epipolar band and disparity range in the
/// right image, placement by placement. Returns the number of matches scoring `min_score`.
#[allow(clippy::too_many_arguments)]
pub fn stereo(
    left: &Gray<'_>,
    right: &Gray<'_>,
    win: Rect,
    disparity: (f32, f32),
    band: usize,
    half: usize,
    min_score: f64,
    corners: (u32, usize, usize),
) -> usize {
    let mut n = 0;
    for (x, y) in strongest(left, win, corners.0, corners.1, corners.2) {
        if x < half || y < half + band || y + half + band >= left.height || x + half >= left.width {
            continue;
        }
        let (lo, hi) = (x as f32 - disparity.1, x as f32 - disparity.0);
        if hi < half as f32 {
            continue;
        }
        let x0 = lo.max(half as f32).floor() as usize - half;
        let x1 = (hi.ceil() as usize + half + 1).min(right.width);
        if x1 - x0 < 2 * half + 1 {
            continue;
        }
        let search = Rect::new(x0, y - half - band, x1, y + half + band + 1);
        if nc_best(right, search, &patch(left, x, y, half)).2 >= min_score {
            n += 1;
        }
    }
    n
}

/// Depth from motion's start-up and first update: the corners of the first frame, each patch
/// correlated over the box round its ray out to `reach` pixels from the focus of expansion.
pub fn depth_first_update(
    first: &Gray<'_>,
    next: &Gray<'_>,
    win: Rect,
    foe: [f32; 2],
    reach: f32,
    half: usize,
    corners: (u32, usize, usize),
) -> usize {
    let mut n = 0;
    for (x, y) in strongest(first, win, corners.0, corners.1, corners.2) {
        if x < half || y < half || x + half >= first.width || y + half >= first.height {
            continue;
        }
        let at = [x as f32 + 0.5, y as f32 + 0.5];
        let (dx, dy) = (at[0] - foe[0], at[1] - foe[1]);
        let r = dx.hypot(dy).max(1e-3);
        let end = [at[0] + dx / r * reach, at[1] + dy / r * reach];
        let pad = 4.0 + half as f32;
        let (x0, y0) = (at[0].min(end[0]) - pad, at[1].min(end[1]) - pad);
        let (x1, y1) = (at[0].max(end[0]) + pad + 1.0, at[1].max(end[1]) + pad + 1.0);
        if x0 < 0.0 || y0 < 0.0 || x1 > next.width as f32 || y1 > next.height as f32 {
            continue;
        }
        let search = Rect::new(x0 as usize, y0 as usize, x1 as usize, y1 as usize);
        if nc_best(next, search, &patch(first, x, y, half)).2 > 0.9 {
            n += 1;
        }
    }
    n
}

/// The constrained Hough transform with one accumulator of 1-pixel cells per hypothesis, every
/// vote placed pixel by pixel along its slide; the strongest cell over all of them.
pub fn hough(lines: &[Line], model: &DockModel, hypotheses: &[Hypothesis], size: [usize; 2]) -> [f32; 2] {
    let (mut best, mut best_v) = ([0.0, 0.0], 0.0f32);
    for h in hypotheses {
        let mut votes = vec![0f32; size[0] * size[1]];
        let (c, s) = (h.rotation.cos(), h.rotation.sin());
        for seg in &model.segments {
            let (dx, dy) = (seg[1][0] - seg[0][0], seg[1][1] - seg[0][1]);
            let seg_len = dx.hypot(dy) * h.scale;
            let dir = (dy * c + dx * s).atan2(dx * c - dy * s);
            let mid = [(seg[0][0] + seg[1][0]) / 2.0, (seg[0][1] + seg[1][1]) / 2.0];
            let offset = [h.scale * (mid[0] * c - mid[1] * s), h.scale * (mid[0] * s + mid[1] * c)];
            for l in lines {
                let ld = (l.to[1] - l.from[1]).atan2(l.to[0] - l.from[0]);
                let turn = (ld - dir).rem_euclid(std::f32::consts::PI);
                if turn.min(std::f32::consts::PI - turn) > 0.17
                    || l.length > 1.3 * seg_len
                    || l.length < 0.3 * seg_len
                {
                    continue;
                }
                let centre = [(l.from[0] + l.to[0]) / 2.0, (l.from[1] + l.to[1]) / 2.0];
                let slack = ((seg_len - l.length) / 2.0).max(0.0);
                let mut t = -slack;
                while t <= slack {
                    let at = [centre[0] - offset[0] + t * dir.cos(), centre[1] - offset[1] + t * dir.sin()];
                    if at[0] >= 0.0
                        && at[1] >= 0.0
                        && (at[0] as usize) < size[0]
                        && (at[1] as usize) < size[1]
                    {
                        votes[at[1] as usize * size[0] + at[0] as usize] += l.length / h.scale;
                    }
                    t += 1.0;
                }
            }
        }
        for (i, &v) in votes.iter().enumerate() {
            if v > best_v {
                (best, best_v) = ([(i % size[0]) as f32, (i / size[0]) as f32], v);
            }
        }
    }
    best
}
