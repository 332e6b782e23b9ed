//! What a depth-from-motion look asks and what its answer places (001 §2.3): the request for a
//! run's look, a tracked point on the floor, the obstacles the points make, and the turn the
//! registration measured as a correction about a point.

use std::collections::BTreeMap;

use harvey_msgs::{Header, Pose2, VisionAlgorithm, VisionRequest};

use crate::mission::DepthGoal;

/// The looks' request id (a new run is told by the request's first parameter).
pub(super) const REQUEST_ID: u32 = 3;

/// A look of a run: its number, its travel along the run's heading (m) and the odometry's turn
/// since the run's start (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Look {
    pub number: u32,
    pub travelled_m: f64,
    pub turned_rad: f64,
}

/// The request for look `how` in window `window_px`.
pub(super) fn request(g: &DepthGoal, window_px: [f64; 4], how: Look, header: Header) -> VisionRequest {
    VisionRequest {
        header,
        request_id: REQUEST_ID,
        algorithm: VisionAlgorithm::Depth as u32,
        standing: 0,
        expected: Pose2 { x_m: how.travelled_m, y_m: 0.0, heading_rad: how.turned_rad },
        window_px: window_px.map(|v| v as f32),
        params: [
            how.number as f32,
            g.min_score as f32,
            g.moravec_threshold as f32,
            g.max_points as f32,
            g.noise_px as f32,
            0.0,
            0.0,
            g.max_rel_sd as f32,
        ],
        ..VisionRequest::default()
    }
}

/// Item `v` (`[u, v, depth, sd, frames, class]`) as a point on the floor, when it is an
/// obstacle judged well enough: seen from `here` (the robot's believed pose) along the run's
/// start heading, the camera having turned since by what the frame's registration `shift_u`
/// says (a visual compass); `camera` the focal length and centre column (px).
pub(super) fn place(
    g: &DepthGoal,
    v: [f64; 6],
    shift_u: f64,
    here: Pose2,
    (focal_px, cx): (f64, f64),
) -> Option<[f64; 2]> {
    let [u, _, z, sd, frames, class] = v;
    let good = class > 0.5
        && frames >= f64::from(g.min_frames)
        && z > 0.0
        && z >= g.min_range_m
        && sd <= g.max_rel_sd * z
        && z <= g.max_range_m;
    if !good {
        return None;
    }
    let turned = (shift_u / focal_px).atan();
    let eye = Pose2 { heading_rad: here.heading_rad - turned, ..here };
    Some(eye.apply([z, -(u - shift_u - cx) * z / focal_px]))
}

/// The rotation by `angle` about `pivot`, as a pose to compose in front of another.
pub(super) fn rotation_about(pivot: Pose2, angle: f64) -> Pose2 {
    let (s, c) = angle.sin_cos();
    Pose2 {
        x_m: pivot.x_m - (c * pivot.x_m - s * pivot.y_m),
        y_m: pivot.y_m - (s * pivot.x_m + c * pivot.y_m),
        heading_rad: angle,
    }
}

/// Groups `points` into obstacles (a point within `link_m` of another is in its group) and
/// gives each group's point nearest `from`.
pub(super) fn nearest_of_each(points: &[[f64; 2]], from: [f64; 2], link_m: f64) -> Vec<[f64; 2]> {
    let mut group: Vec<usize> = (0..points.len()).collect();
    let root = |g: &[usize], mut i: usize| {
        while g[i] != i {
            i = g[i];
        }
        i
    };
    for i in 0..points.len() {
        for j in 0..i {
            let (a, b) = (points[i], points[j]);
            if (a[0] - b[0]).hypot(a[1] - b[1]) <= link_m {
                let (ri, rj) = (root(&group, i), root(&group, j));
                group[ri] = rj;
            }
        }
    }
    let mut nearest: BTreeMap<usize, [f64; 2]> = BTreeMap::new();
    let d = |p: [f64; 2]| (p[0] - from[0]).hypot(p[1] - from[1]);
    for (i, &p) in points.iter().enumerate() {
        let r = root(&group, i);
        let e = nearest.entry(r).or_insert(p);
        if d(p) < d(*e) {
            *e = p;
        }
    }
    nearest.into_values().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_group_into_obstacles_each_pushing_from_its_nearest() {
        // A cone's three points and a bin's two, 2 m apart; the robot at the origin.
        let points = [[5.0, 0.1], [5.2, 0.0], [5.1, -0.1], [7.0, 2.0], [7.3, 2.1]];
        let mut nearest = nearest_of_each(&points, [0.0, 0.0], 0.5);
        nearest.sort_by(|a, b| a[0].total_cmp(&b[0]));
        assert_eq!(nearest, vec![[5.0, 0.1], [7.0, 2.0]]);
        // Linked in a chain, they are one obstacle.
        assert_eq!(nearest_of_each(&points, [0.0, 0.0], 3.0).len(), 1);
        assert!(nearest_of_each(&[], [0.0, 0.0], 0.5).is_empty());
    }

    #[test]
    fn a_rotation_about_a_point_keeps_it_and_turns_the_rest() {
        let pivot = Pose2 { x_m: 2.0, y_m: 1.0, heading_rad: 0.3 };
        let r = rotation_about(pivot, std::f64::consts::FRAC_PI_2);
        let kept = r.apply([2.0, 1.0]);
        assert!((kept[0] - 2.0).abs() < 1e-12 && (kept[1] - 1.0).abs() < 1e-12, "{kept:?}");
        // A point a metre ahead of the pivot along x ends a metre along y from it.
        let turned = r.apply([3.0, 1.0]);
        assert!((turned[0] - 2.0).abs() < 1e-12 && (turned[1] - 2.0).abs() < 1e-12, "{turned:?}");
    }

    fn goal() -> DepthGoal {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../missions/depth-obstacles.toml"
        ))
        .expect("the mission");
        crate::mission::parse(&text, "depth-obstacles.toml").expect("parses").depth.expect("[mission.depth]")
    }

    #[test]
    fn an_obstacle_point_is_placed_where_its_depth_and_column_say() {
        let g = goal();
        let here = Pose2 { x_m: 1.0, y_m: 0.0, heading_rad: 0.0 };
        // Straight ahead at 4 m, judged standing, sharp: 4 m on along x.
        let p = place(&g, [320.0, 300.0, 4.0, 0.1, 5.0, 1.0], 0.0, here, (554.0, 320.0)).expect("placed");
        assert!((p[0] - 5.0).abs() < 1e-9 && p[1].abs() < 1e-9, "{p:?}");
        // 55.4 px right of centre at 4 m: 0.4 m to the right (negative y).
        let p = place(&g, [375.4, 300.0, 4.0, 0.1, 5.0, 1.0], 0.0, here, (554.0, 320.0)).expect("placed");
        assert!((p[1] + 0.4).abs() < 1e-9, "{p:?}");
        // The same point in a frame shifted by the camera's turn lands in the same place.
        let shift = 554.0 * 0.05f64.tan();
        let turned = Pose2 { heading_rad: 0.05, ..here };
        let q = place(&g, [375.4 + shift, 300.0, 4.0, 0.1, 5.0, 1.0], shift, turned, (554.0, 320.0))
            .expect("placed");
        assert!((q[0] - p[0]).abs() < 1e-9 && (q[1] - p[1]).abs() < 1e-9, "{q:?} vs {p:?}");
        // On the floor, unsure, too few looks, beyond range or nearer than the camera's points
        // are trusted: not an obstacle.
        for v in [
            [320.0, 300.0, 4.0, 0.1, 5.0, 0.0],
            [320.0, 300.0, 4.0, 0.9, 5.0, 1.0],
            [320.0, 300.0, 4.0, 0.1, 2.0, 1.0],
            [320.0, 300.0, 9.0, 0.1, 5.0, 1.0],
            [391.0, 395.0, 0.82, 0.01, 3.0, 1.0],
        ] {
            assert_eq!(place(&g, v, 0.0, here, (554.0, 320.0)), None, "{v:?}");
        }
    }
}
