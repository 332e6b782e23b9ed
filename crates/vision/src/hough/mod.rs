//! The constrained Hough transform of 004 §4.1.2 (after Vaughn and Arkin): a line model of the
//! dock, a few scale and orientation hypotheses from the spatial uncertainty, every image line
//! voting in one image-coordinate Hough space for where the model's reference point must be;
//! the strongest peaks are verified by how much of the model the lines cover (`verify.rs`), and
//! the end posts' heights read for the inverse perspective (`posts.rs`).

mod posts;
mod verify;

pub use posts::post_heights;

use crate::flf::Line;

/// Peaks of the vote space verified: an end post votes for its own place under every scale, so
/// the strongest peak is often a post rather than the frame's centre.
const PEAKS: usize = 6;
/// Peaks with less than this share of the strongest's votes are not verified.
const WEAKEST: f32 = 0.33;
/// Peaks closer than this many cells to a stronger one are the same peak.
const PEAK_APART: usize = 2;

/// A line model of the dock: segments in model units around its reference point (origin).
#[derive(Debug, Clone, PartialEq)]
pub struct DockModel {
    pub segments: Vec<[[f32; 2]; 2]>,
}

impl DockModel {
    /// A dock front as a 2 x 1 frame with a centre post, reference point at its centre (the
    /// shape the docking tests and the bench use).
    pub fn frame_with_post() -> Self {
        let s = |a: [f32; 2], b: [f32; 2]| [a, b];
        Self {
            segments: vec![
                s([-1.0, -0.5], [1.0, -0.5]),
                s([-1.0, 0.5], [1.0, 0.5]),
                s([-1.0, -0.5], [-1.0, 0.5]),
                s([1.0, -0.5], [1.0, 0.5]),
                s([0.0, -0.5], [0.0, 0.5]),
            ],
        }
    }
}

/// One scale and orientation the dock may appear at (from the spatial uncertainty).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hypothesis {
    /// Pixels per model unit.
    pub scale: f32,
    /// Image rotation of the model (radians).
    pub rotation: f32,
}

/// Where the dock is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DockMatch {
    /// The model's reference point in the image.
    pub at: [f32; 2],
    /// The share of the model's length that image lines cover, the model placed at `at` with
    /// `scale` and `rotation` (0..1).
    pub certainty: f32,
    /// Pixels per model unit, fitted to the lines.
    pub scale: f32,
    /// The image rotation of the hypothesis that fitted.
    pub rotation: f32,
}

/// The transform's working space, kept between calls: it stops allocating once grown.
#[derive(Debug, Default)]
pub struct HoughScratch {
    votes: Vec<f32>,
    near: Vec<Line>,
}

/// The constrained Hough transform: each image line votes, for every hypothesis and every
/// model segment of like orientation and length, for where the reference point must then be;
/// all hypotheses share one Hough space in image coordinates, `cell` pixels a bin. The
/// `PEAKS` strongest peaks are verified over the hypotheses' range of scales; the one the image
/// lines cover best is the match.
pub fn find_dock(
    lines: &[Line],
    model: &DockModel,
    hypotheses: &[Hypothesis],
    image: [usize; 2],
    cell: f32,
    scratch: &mut HoughScratch,
) -> Option<DockMatch> {
    if model.segments.is_empty() || hypotheses.is_empty() || cell.is_nan() || cell < 1.0 {
        return None;
    }
    let (bw, bh) = ((image[0] as f32 / cell).ceil() as usize, (image[1] as f32 / cell).ceil() as usize);
    let votes = &mut scratch.votes;
    votes.clear();
    votes.resize(bw * bh, 0.0);
    for hyp in hypotheses {
        let (c, s) = (hyp.rotation.cos(), hyp.rotation.sin());
        for seg in &model.segments {
            let mid = [(seg[0][0] + seg[1][0]) / 2.0, (seg[0][1] + seg[1][1]) / 2.0];
            let (dx, dy) = (seg[1][0] - seg[0][0], seg[1][1] - seg[0][1]);
            let seg_len = dx.hypot(dy) * hyp.scale;
            let seg_dir = (dy * c + dx * s).atan2(dx * c - dy * s);
            let offset = [hyp.scale * (mid[0] * c - mid[1] * s), hyp.scale * (mid[0] * s + mid[1] * c)];
            for l in lines {
                let line_dir = (l.to[1] - l.from[1]).atan2(l.to[0] - l.from[0]);
                let mut turn = (line_dir - seg_dir).rem_euclid(std::f32::consts::PI);
                turn = turn.min(std::f32::consts::PI - turn);
                // Like orientation (within 10 degrees) and a length it could be a piece of.
                if turn > 0.17 || l.length > 1.3 * seg_len || l.length < 0.3 * seg_len {
                    continue;
                }
                // A fragment may lie anywhere along its segment: it votes, with its length in
                // model units, for every reference point it allows (one cell apart).
                let centre = [(l.from[0] + l.to[0]) / 2.0, (l.from[1] + l.to[1]) / 2.0];
                let slack = ((seg_len - l.length) / 2.0).max(0.0);
                let steps = (2.0 * slack / cell).ceil().max(1.0) as usize;
                let (ux, uy) = (seg_dir.cos(), seg_dir.sin());
                let v = l.length / hyp.scale;
                for k in 0..steps {
                    let slide =
                        if steps == 1 { 0.0 } else { -slack + 2.0 * slack * k as f32 / (steps - 1) as f32 };
                    let at = [centre[0] - offset[0] + slide * ux, centre[1] - offset[1] + slide * uy];
                    if at[0] < 0.0 || at[1] < 0.0 {
                        continue;
                    }
                    let (bx, by) = ((at[0] / cell) as usize, (at[1] / cell) as usize);
                    if bx < bw && by < bh {
                        votes[by * bw + bx] += v;
                    }
                }
            }
        }
    }
    let mut best: Option<DockMatch> = None;
    for at in peaks(votes, bw, bh, cell).into_iter().flatten() {
        let m = verify::verify(lines, model, hypotheses, at, cell, &mut scratch.near);
        if let Some(m) = m.filter(|m| best.is_none_or(|b| m.certainty > b.certainty)) {
            best = Some(m);
        }
    }
    best
}

/// The `PEAKS` strongest peaks of the votes smoothed over 2x2 neighbourhoods (a reference point
/// near a bin edge splits its votes), each at least `PEAK_APART` cells from a stronger one, as
/// the vote-weighted centres of their 2x2 cells.
fn peaks(votes: &[f32], bw: usize, bh: usize, cell: f32) -> [Option<[f32; 2]>; PEAKS] {
    let smooth = |bx: usize, by: usize| {
        votes[by * bw + bx]
            + votes[by * bw + bx + 1]
            + votes[(by + 1) * bw + bx]
            + votes[(by + 1) * bw + bx + 1]
    };
    let mut found = [None; PEAKS];
    let mut taken: [(usize, usize); PEAKS] = [(usize::MAX, usize::MAX); PEAKS];
    let mut first_v = 0.0f32;
    for k in 0..PEAKS {
        let (mut best, mut best_v) = ((0, 0), 0.0f32);
        for by in 0..bh.saturating_sub(1) {
            for bx in 0..bw.saturating_sub(1) {
                let near_taken = taken[..k]
                    .iter()
                    .any(|&(tx, ty)| tx.abs_diff(bx) <= PEAK_APART && ty.abs_diff(by) <= PEAK_APART);
                let v = smooth(bx, by);
                if v > best_v && !near_taken {
                    (best, best_v) = ((bx, by), v);
                }
            }
        }
        // A peak of under a third of the strongest's votes is not the dock.
        let strongest = taken[0].0 != usize::MAX;
        if best_v <= 0.0 || strongest && best_v < WEAKEST * first_v {
            break;
        }
        if !strongest {
            first_v = best_v;
        }
        taken[k] = best;
        let (bx, by) = best;
        let (mut sx, mut sy) = (0.0, 0.0);
        for (x, y) in [(bx, by), (bx + 1, by), (bx, by + 1), (bx + 1, by + 1)] {
            let v = votes[y * bw + x];
            sx += v * (x as f32 + 0.5) * cell;
            sy += v * (y as f32 + 0.5) * cell;
        }
        found[k] = Some([sx / best_v, sy / best_v]);
    }
    found
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn line(from: [f32; 2], to: [f32; 2]) -> Line {
        let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
        Line {
            from,
            to,
            length: dx.hypot(dy),
            orientation_deg: dy.atan2(dx).to_degrees().rem_euclid(180.0),
            mean_gradient: 50.0,
            dispersion: 0.5,
            pixels: dx.hypot(dy) as u32,
        }
    }

    fn dock() -> DockModel {
        DockModel::frame_with_post()
    }

    /// The dock seen at `scale`, `rotation` about `at`, each segment broken in two with a gap and
    /// jittered by up to a pixel, plus clutter.
    fn scene(at: [f32; 2], scale: f32, rotation: f32, with_dock: bool) -> Vec<Line> {
        let (c, s) = (rotation.cos(), rotation.sin());
        let map =
            |p: [f32; 2]| [at[0] + scale * (p[0] * c - p[1] * s), at[1] + scale * (p[0] * s + p[1] * c)];
        let mut out = Vec::new();
        let mut k = 0.0f32;
        if with_dock {
            for seg in dock().segments {
                let (a, b) = (map(seg[0]), map(seg[1]));
                let lerp = |t: f32| {
                    [a[0] + t * (b[0] - a[0]) + (k * 1.7).sin(), a[1] + t * (b[1] - a[1]) + (k * 2.3).cos()]
                };
                out.push(line(lerp(0.0), lerp(0.45)));
                out.push(line(lerp(0.55), lerp(1.0)));
                k += 1.0;
            }
        }
        // Clutter: door frames and floor edges elsewhere.
        for (a, b) in [
            ([30.0, 20.0], [30.0, 200.0]),
            ([500.0, 50.0], [620.0, 60.0]),
            ([100.0, 400.0], [300.0, 380.0]),
            ([560.0, 300.0], [560.0, 420.0]),
            ([40.0, 300.0], [90.0, 300.0]),
        ] {
            out.push(line(a, b));
        }
        out
    }

    #[test]
    fn the_hough_finds_the_dock_among_clutter_and_says_when_it_is_not_there() {
        let hyps: Vec<Hypothesis> = [30.0, 35.0, 40.0, 45.0, 50.0]
            .iter()
            .map(|&scale| Hypothesis { scale, rotation: 0.05 })
            .collect();
        let truth = [321.0, 243.0];
        let mut scratch = HoughScratch::default();
        let m = find_dock(&scene(truth, 41.0, 0.06, true), &dock(), &hyps, [640, 480], 4.0, &mut scratch)
            .expect("found");
        assert!((m.at[0] - truth[0]).hypot(m.at[1] - truth[1]) < 3.0, "{m:?}");
        assert!(m.certainty > 0.8, "{m:?}");
        assert!((m.scale - 41.0).abs() <= 2.0, "between the hypotheses' scales (the jitter as below): {m:?}");
        let none = find_dock(&scene(truth, 41.0, 0.06, false), &dock(), &hyps, [640, 480], 4.0, &mut scratch);
        assert!(none.is_none_or(|m| m.certainty < 0.3), "{none:?}");
    }

    #[test]
    fn a_dock_between_coarse_hypotheses_is_found_at_its_own_scale() {
        // Hypotheses 20 px a unit apart (the believed distance +-1.22 m at 2.5-3.5 m): the
        // dock at 41 px a unit lies between two of them, as it does in most docking frames.
        let hyps: Vec<Hypothesis> =
            [30.0, 50.0, 70.0].iter().map(|&scale| Hypothesis { scale, rotation: 0.0 }).collect();
        let mut scratch = HoughScratch::default();
        for truth in [[321.0, 243.0], [150.5, 300.0], [480.0, 120.0]] {
            let m = find_dock(&scene(truth, 41.0, 0.0, true), &dock(), &hyps, [640, 480], 4.0, &mut scratch)
                .expect("found");
            assert!((m.at[0] - truth[0]).hypot(m.at[1] - truth[1]) < 3.0, "{truth:?} {m:?}");
            // The scene's jitter moves the bars 1.7 px nearer together (a scale of 39.3 fits
            // them) and the end posts 0.7 px.
            assert!((m.scale - 41.0).abs() <= 2.0, "{m:?}");
            assert!(m.certainty > 0.8, "{m:?}");
        }
    }
}
