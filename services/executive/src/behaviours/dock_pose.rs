//! Where the robot stands relative to the dock: its pose from the Hough's frame (the inverse
//! perspective of 004 §4.1.3 on the end posts) and its distance from the dock's face.

use harvey_msgs::Pose2;

use harvey_geometry::wrap;

use crate::mission::DockingGoal;

/// The robot's pose from the dock recognised in the image (the inverse perspective of 004
/// §4.1.3 on the Hough's frame): the end posts' apparent heights `item[4..6]` give their depths,
/// their difference the angle the face is seen at, their mean the frame's depth, and the frame
/// centre's column `item[0]` its bearing. `None` without both posts, or with a post whose height
/// disagrees with the match's scale by more than a third (a post cut short or lengthened by
/// something in front of the dock), or seen at more than 35 degrees.
pub fn pose_from_dock(g: &DockingGoal, focal_px: f64, centre_u: f64, item: &[f64; 6]) -> Option<Pose2> {
    let [u, _, _, scale, left, right] = *item;
    let plausible = |h: f64| (0.75 * scale..1.33 * scale).contains(&h);
    if !plausible(left) || !plausible(right) {
        return None;
    }
    let post_m = g.frame_width_m / 2.0;
    let (z_left, z_right) = (focal_px * post_m / left, focal_px * post_m / right);
    let sin_turned = (z_left - z_right) / g.frame_width_m;
    if sin_turned.abs() > 0.57 {
        return None;
    }
    let turned = sin_turned.asin();
    let heading = wrap(g.dock_facing_deg.to_radians() + std::f64::consts::PI + turned);
    let bearing = ((centre_u - u) / focal_px).atan();
    let ray = (z_left + z_right) / 2.0 / bearing.cos();
    let a = heading + bearing;
    Some(Pose2 { x_m: g.dock_m[0] - ray * a.cos(), y_m: g.dock_m[1] - ray * a.sin(), heading_rad: heading })
}

/// The face's distance from `at` along the face's normal (the robot's centre to the face).
pub(crate) fn face_distance(g: &DockingGoal, at: Pose2) -> f64 {
    let n = g.dock_facing_deg.to_radians();
    (at.x_m - g.dock_m[0]) * n.cos() + (at.y_m - g.dock_m[1]) * n.sin()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn goal() -> DockingGoal {
        let text =
            std::fs::read_to_string(format!("{}/../../missions/docking.toml", env!("CARGO_MANIFEST_DIR")))
                .expect("readable");
        crate::mission::parse(&text, "docking.toml").expect("parses").docking.expect("docking")
    }

    /// The Hough's item for a robot at `at`: frame centre column, scale, and the end posts'
    /// heights (left post at y = +0.5, on the robot's left when it faces the dock).
    fn seen_from(at: Pose2, f: f64) -> [f64; 6] {
        let (c, s) = (at.heading_rad.cos(), at.heading_rad.sin());
        let depth = |p: [f64; 2]| (p[0] - at.x_m) * c + (p[1] - at.y_m) * s;
        let left_of = |p: [f64; 2]| -(p[0] - at.x_m) * s + (p[1] - at.y_m) * c;
        let centre = [13.6, 0.0];
        let u = 320.0 - f * left_of(centre) / depth(centre);
        [u, 200.0, 0.9, f * 0.5 / depth(centre), f * 0.5 / depth([13.6, 0.5]), f * 0.5 / depth([13.6, -0.5])]
    }

    #[test]
    fn the_frame_s_posts_and_centre_give_the_robot_s_pose() {
        let g = goal();
        for truth in [
            Pose2 { x_m: 10.0, y_m: -0.5, heading_rad: 10f64.to_radians() },
            Pose2 { x_m: 9.0, y_m: 1.2, heading_rad: -20f64.to_radians() },
            Pose2 { x_m: 11.5, y_m: 0.0, heading_rad: 0.0 },
        ] {
            let p = pose_from_dock(&g, 554.0, 320.0, &seen_from(truth, 554.0)).expect("a pose");
            assert!((p.x_m - truth.x_m).abs() < 1e-9 && (p.y_m - truth.y_m).abs() < 1e-9, "{p:?} {truth:?}");
            assert!((p.heading_rad - truth.heading_rad).abs() < 1e-9, "{p:?} {truth:?}");
        }
        // A post cut short by something in front of it: no pose.
        let mut cut = seen_from(Pose2 { x_m: 10.0, y_m: 0.0, heading_rad: 0.0 }, 554.0);
        cut[4] *= 0.6;
        assert_eq!(pose_from_dock(&g, 554.0, 320.0, &cut), None);
    }
}
