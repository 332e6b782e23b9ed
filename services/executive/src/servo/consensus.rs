//! Which matches of a pose fix to start from: the largest set that agrees with the pose some
//! pair of them gives (every pair tried: at most 16 vertices are asked for, so 120 pairs), to
//! within a gross gate. A vertex's template may correlate as well with a look-alike elsewhere in
//! the image (another corner of the same paint on the same wall) as with the vertex, tens to
//! hundreds of pixels from it; a few such matches pull a solution from all of them away from the
//! good ones, and dropping the worst from there can keep the wrong ones. The fine gate
//! (`RefineParams::gate_px`) is left to the refinement, which drops the worst from this set.

use harvey_msgs::Pose2;

use crate::servo::pose::{
    PinholeCamera, RefineParams, SURPRISE_LIMIT, VertexMatch, fit, residual_px, surprise,
};

/// The gross gate, in fine gates (12 px for the missions' 3 px): a match further from the pose
/// a pair gives is a look-alike, not a vertex the map has a little wrong. A painted region
/// shifted three standard deviations of the harsh condition's 2 cm survey error, 3 m off, is
/// 11 px out; the look-alikes seen in the office were 60-270 px out.
pub const GROSS_GATES: f64 = 4.0;

/// The indices of the matches within the gross gate of the pose and pitch fitted to a pair and
/// then to the matches that agree with it, for the pair whose fit the most matches agree with
/// (ties: the smaller sum of their squared residuals, then the first pair), of the pairs whose
/// fit the prior allows; every index when no pair does or there are fewer than three.
pub fn agreeing(
    cam: &PinholeCamera,
    expected: Pose2,
    matches: &[VertexMatch],
    p: &RefineParams,
) -> Vec<usize> {
    let all: Vec<usize> = (0..matches.len()).collect();
    if matches.len() < 3 {
        return all;
    }
    let gross = GROSS_GATES * p.gate_px;
    let within = |pose: Pose2, pitch: f64| {
        let (mut set, mut cost) = (Vec::new(), 0.0);
        for (k, m) in matches.iter().enumerate() {
            let r = residual_px(cam, pose, pitch, m);
            if r <= gross {
                set.push(k);
                cost += r * r;
            }
        }
        (set, cost)
    };
    let mut best: Option<(Vec<usize>, f64)> = None;
    for i in 0..matches.len() {
        for j in i + 1..matches.len() {
            let Some((pose, pitch)) = fit(cam, expected, matches, &[i, j], p) else { continue };
            // A pose the prior rules out is no hypothesis (look-alikes may agree with each other:
            // the corners of one paint all taken for a neighbouring paint's).
            if surprise(pose, expected, p.prior_sd) > SURPRISE_LIMIT {
                continue;
            }
            // Two matches' noise carries far: the pose fitted to those that agree with theirs
            // says which agree (once).
            let (mut set, mut cost) = within(pose, pitch);
            if set.len() > 2
                && let Some((pose, pitch)) = fit(cam, expected, matches, &set, p)
                && surprise(pose, expected, p.prior_sd) <= SURPRISE_LIMIT
            {
                (set, cost) = within(pose, pitch);
            }
            let better =
                best.as_ref().is_none_or(|(b, c)| set.len() > b.len() || (set.len() == b.len() && cost < *c));
            if better {
                best = Some((set, cost));
            }
        }
    }
    best.map_or(all, |(set, _)| set)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::servo::pose::tests::{cam, params};

    /// Matches of `vertices` seen from `truth`, the ones in `swapped` found where the next one
    /// lies instead (a look-alike: another corner of the same paint).
    fn seen(truth: Pose2, vertices: &[[f64; 3]], swapped: &[usize]) -> Vec<VertexMatch> {
        let at = |k: usize| cam().project(truth, vertices[k]).expect("in view");
        (0..vertices.len())
            .map(|k| VertexMatch {
                world_m: vertices[k],
                image_px: if swapped.contains(&k) { at((k + 1) % vertices.len()) } else { at(k) },
            })
            .collect()
    }

    fn office() -> Vec<[f64; 3]> {
        vec![
            [4.0, 1.5, 1.8],
            [4.0, 0.8, 1.8],
            [4.0, 1.5, 0.9],
            [4.0, 0.8, 0.9],
            [4.0, -0.5, 2.0],
            [4.0, -1.2, 2.0],
            [3.0, 2.0, 0.3],
            [3.5, 2.0, 1.2],
            [5.0, -0.2, 1.1],
            [5.0, 0.4, 1.1],
        ]
    }

    #[test]
    fn look_alikes_are_left_out_and_the_true_matches_kept() {
        let truth = Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: 0.0 };
        let expected = Pose2 { x_m: -0.1, y_m: 0.08, heading_rad: 0.03 };
        // Four of ten taken for a neighbour tens of pixels away.
        let m = seen(truth, &office(), &[1, 4, 6, 8]);
        let mut set = agreeing(&cam(), expected, &m, &params());
        set.sort_unstable();
        assert_eq!(set, [0, 2, 3, 5, 7, 9]);
        // And the refinement from them lands on the truth.
        let done = crate::servo::pose::refine(&cam(), expected, &m, &params()).expect("a fix");
        assert!(done.pose.distance(&truth) < 0.01 && done.kept.len() == 6, "{done:?}");
    }

    #[test]
    fn with_every_match_good_all_are_kept_and_too_few_to_choose_from_are_all_kept() {
        let truth = Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: 0.0 };
        let expected = Pose2 { x_m: 0.1, y_m: -0.1, heading_rad: -0.02 };
        let m = seen(truth, &office(), &[]);
        assert_eq!(agreeing(&cam(), expected, &m, &params()).len(), m.len());
        assert_eq!(agreeing(&cam(), expected, &m[..2], &params()), [0, 1]);
    }
}
