//! The constrained Hough transform of 004 §4.1.2 (after Vaughn and Arkin): a line model of the
//! dock, a few scale and orientation hypotheses from the spatial uncertainty, every image line
//! voting in one image-coordinate Hough space for where the model's reference point must be;
//! the peak is verified by how much of the model the lines cover.

use crate::flf::Line;

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
    /// The share of the model's length that image lines cover, placed at the peak under the
    /// best hypothesis (0..1).
    pub certainty: f32,
    /// Index of that hypothesis.
    pub hypothesis: usize,
}

/// The constrained Hough transform: each image line votes, for every hypothesis and every
/// model segment of like orientation and length, for where the reference point must then be;
/// all hypotheses share one Hough space in image coordinates, `cell` pixels a bin. `votes` is
/// the caller's scratch space (kept between calls, it stops allocating once grown).
pub fn find_dock(
    lines: &[Line],
    model: &DockModel,
    hypotheses: &[Hypothesis],
    image: [usize; 2],
    cell: f32,
    votes: &mut Vec<f32>,
) -> Option<DockMatch> {
    if model.segments.is_empty() || hypotheses.is_empty() || cell.is_nan() || cell < 1.0 {
        return None;
    }
    let (bw, bh) = ((image[0] as f32 / cell).ceil() as usize, (image[1] as f32 / cell).ceil() as usize);
    votes.clear();
    votes.resize(bw * bh, 0.0);
    let model_len: f32 = model.segments.iter().map(|s| (s[1][0] - s[0][0]).hypot(s[1][1] - s[0][1])).sum();
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
    // Smooth over 2x2 neighbourhoods: a reference point near a bin edge splits its votes.
    let (mut best, mut best_v) = ((0, 0), 0.0f32);
    for by in 0..bh.saturating_sub(1) {
        for bx in 0..bw.saturating_sub(1) {
            let v = votes[by * bw + bx]
                + votes[by * bw + bx + 1]
                + votes[(by + 1) * bw + bx]
                + votes[(by + 1) * bw + bx + 1];
            if v > best_v {
                (best, best_v) = ((bx, by), v);
            }
        }
    }
    if best_v <= 0.0 {
        return None;
    }
    let (bx, by) = best;
    let cells = [(bx, by), (bx + 1, by), (bx, by + 1), (bx + 1, by + 1)];
    let (mut sx, mut sy) = (0.0, 0.0);
    for &(x, y) in &cells {
        let v = votes[y * bw + x];
        sx += v * (x as f32 + 0.5) * cell;
        sy += v * (y as f32 + 0.5) * cell;
    }
    // Verify: the hypothesis whose model, placed at the peak, the image lines cover best.
    let at = [sx / best_v, sy / best_v];
    let (hypothesis, certainty) = hypotheses
        .iter()
        .enumerate()
        .map(|(k, h)| (k, coverage(lines, model, h, at) / model_len))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    Some(DockMatch { at, certainty: certainty.min(1.0), hypothesis })
}

/// Model length (in model units) that image lines cover when the model is placed at `at` under
/// `h`: lines of like orientation within 3 px of a model segment, by their overlap along it.
fn coverage(lines: &[Line], model: &DockModel, h: &Hypothesis, at: [f32; 2]) -> f32 {
    let (c, s) = (h.rotation.cos(), h.rotation.sin());
    let map =
        |p: [f32; 2]| [at[0] + h.scale * (p[0] * c - p[1] * s), at[1] + h.scale * (p[0] * s + p[1] * c)];
    let mut covered = 0.0;
    for seg in &model.segments {
        let (a, b) = (map(seg[0]), map(seg[1]));
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        if len <= 0.0 {
            continue;
        }
        let (ux, uy) = ((b[0] - a[0]) / len, (b[1] - a[1]) / len);
        let along = |p: [f32; 2]| (p[0] - a[0]) * ux + (p[1] - a[1]) * uy;
        let across = |p: [f32; 2]| ((p[0] - a[0]) * uy - (p[1] - a[1]) * ux).abs();
        let mut here = 0.0;
        for l in lines {
            if across(l.from) > 3.0 || across(l.to) > 3.0 {
                continue;
            }
            let (t0, t1) = (along(l.from).min(along(l.to)), along(l.from).max(along(l.to)));
            here += (t1.min(len) - t0.max(0.0)).max(0.0);
        }
        covered += here.min(len) / h.scale;
    }
    covered
}

/// The apparent heights (pixels) of the frame's end posts, left then right, for a match at `at`
/// with `scale` pixels per model unit: the longest near-vertical line near each post (0 where
/// none). A frame turned away shows its far post shorter: with the posts' true height and
/// spacing this gives the angle it is seen at (the inverse perspective cue of 004 §4.1.3).
pub fn post_heights(lines: &[Line], at: [f32; 2], scale: f32) -> [f32; 2] {
    let mut out = [0.0f32; 2];
    for (k, side) in [-1.0f32, 1.0].into_iter().enumerate() {
        let post_u = at[0] + side * scale;
        out[k] = lines
            .iter()
            .filter(|l| (l.orientation_deg - 90.0).abs() < 10.0)
            .filter(|l| {
                let mid = [(l.from[0] + l.to[0]) / 2.0, (l.from[1] + l.to[1]) / 2.0];
                (mid[0] - post_u).abs() < 0.25 * scale && (mid[1] - at[1]).abs() < 0.35 * scale
            })
            .map(|l| l.length)
            .fold(0.0, f32::max);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(from: [f32; 2], to: [f32; 2]) -> Line {
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
        let m = find_dock(&scene(truth, 41.0, 0.06, true), &dock(), &hyps, [640, 480], 4.0, &mut Vec::new())
            .expect("found");
        assert!((m.at[0] - truth[0]).hypot(m.at[1] - truth[1]) < 4.0, "{m:?}");
        assert!(m.certainty > 0.6, "{m:?}");
        assert_eq!(hyps[m.hypothesis].scale, 40.0, "{m:?}");
        let none =
            find_dock(&scene(truth, 41.0, 0.06, false), &dock(), &hyps, [640, 480], 4.0, &mut Vec::new());
        assert!(none.is_none_or(|m| m.certainty < 0.3), "{none:?}");
    }

    #[test]
    fn the_posts_heights_are_read_from_the_lines_near_them() {
        // Left post 60 px tall, right post 66 px (the right is nearer), both broken by noise into
        // a long and a short piece; a vertical line elsewhere is ignored.
        let lines = [
            line([100.0, 170.0], [100.0, 230.0]),
            line([100.0, 150.0], [100.0, 160.0]),
            line([220.0, 167.0], [220.0, 233.0]),
            line([160.0, 100.0], [160.0, 300.0]),
            line([215.0, 200.0], [240.0, 200.0]),
        ];
        assert_eq!(post_heights(&lines, [160.0, 200.0], 60.0), [60.0, 66.0]);
        assert_eq!(post_heights(&lines, [400.0, 200.0], 60.0), [0.0, 0.0]);
    }
}
