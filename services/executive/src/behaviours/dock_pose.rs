//! Where the robot stands relative to the dock: its pose from the Hough's frame (the inverse
//! perspective of 004 §4.1.3 on the end posts) and its distance from the dock's face.

use harvey_msgs::Pose2;

use harvey_geometry::wrap;

use super::region::Region;
use crate::mission::DockingGoal;

/// What the dock recognised in the image says (the inverse perspective of 004 §4.1.3 on the
/// Hough's frame): the robot's heading, with its standard deviation, and the frame centre's range
/// and bearing from the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DockSight {
    pub heading_rad: f64,
    pub heading_sd_rad: f64,
    pub ray_m: f64,
    pub bearing_rad: f64,
}

impl DockSight {
    /// The robot's pose with heading `heading_rad`: the frame's centre seen along the bearing at
    /// the range.
    pub fn pose(&self, g: &DockingGoal, heading_rad: f64) -> Pose2 {
        let a = heading_rad + self.bearing_rad;
        Pose2 {
            x_m: g.dock_m[0] - self.ray_m * a.cos(),
            y_m: g.dock_m[1] - self.ray_m * a.sin(),
            heading_rad,
        }
    }
}

/// The dock in the Hough's item: the end posts' apparent heights `item[4..6]` give their
/// depths, their difference the angle the face is seen at (the heading, uncertain by
/// `post_height_sd_px` on each post: at 4-5 m a pixel is about 5 degrees), their mean the frame's
/// depth, and the frame centre's column `item[0]` its bearing. `None` without both posts, or with
/// a post whose height disagrees with the match's scale by more than a third (a post cut short or
/// lengthened by something in front of the dock), or seen at more than 35 degrees.
pub fn dock_sight(g: &DockingGoal, focal_px: f64, centre_u: f64, item: &[f64; 6]) -> Option<DockSight> {
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
    let heading_rad = wrap(g.dock_facing_deg.to_radians() + std::f64::consts::PI + turned);
    let sd_sin = (z_left / left).hypot(z_right / right) * g.post_height_sd_px / g.frame_width_m;
    let bearing_rad = ((centre_u - u) / focal_px).atan();
    let ray_m = (z_left + z_right) / 2.0 / bearing_rad.cos();
    Some(DockSight { heading_rad, heading_sd_rad: sd_sin / turned.cos(), ray_m, bearing_rad })
}

/// A fix from `s`: its heading weighed against the belief's (`believed`, of variance `prior` as
/// of the last fix, `None` before the first, grown by odometry's drift over `travelled_m`), and
/// the pose the frame's range and bearing give at the weighed heading; with the heading's new
/// variance. A pixel of post height is some 5 degrees of heading at 4-5 m, while odometry
/// drifts about a degree a metre: taken whole, each fix threw the heading about by several
/// degrees, and the runs ended up to 14 degrees off square.
pub fn weighed_fix(
    g: &DockingGoal,
    s: &DockSight,
    believed: Pose2,
    prior: Option<f64>,
    travelled_m: f64,
) -> (Pose2, f64) {
    let fix_var = s.heading_sd_rad.powi(2);
    let Some(prior) = prior else { return (s.pose(g, s.heading_rad), fix_var) };
    let drift = g.heading_drift_deg_per_m.to_radians() * travelled_m;
    let var = prior + drift * drift;
    let k = var / (var + fix_var);
    (s.pose(g, believed.heading_rad + k * wrap(s.heading_rad - believed.heading_rad)), (1.0 - k) * var)
}

/// The face's distance from `at` along the face's normal (the robot's centre to the face).
pub(crate) fn face_distance(g: &DockingGoal, at: Pose2) -> f64 {
    let n = g.dock_facing_deg.to_radians();
    (at.x_m - g.dock_m[0]) * n.cos() + (at.y_m - g.dock_m[1]) * n.sin()
}

/// The distances from the dock's face the robot, believed `d` from it, may be at (near, far):
/// over the UMS's `region` (and the belief), widened by `hough_band_min_m` either way; the
/// paper's "plus or minus four feet" (`hough_range_sd_m`) while the UMS has published none.
pub(crate) fn hough_band(g: &DockingGoal, region: Option<&Region>, d: f64) -> (f64, f64) {
    let (near, far) = match region {
        Some(region) => {
            let (lo, hi) =
                region.span(|p| face_distance(g, Pose2 { x_m: p[0], y_m: p[1], heading_rad: 0.0 }));
            (lo.min(d) - g.hough_band_min_m, hi.max(d) + g.hough_band_min_m)
        }
        None => (d - g.hough_range_sd_m, d + g.hough_range_sd_m),
    };
    // A region that does not give a band (a vertex not finite) falls back to the paper's spread.
    let (near, far) = if near.is_finite() && far.is_finite() && near <= far {
        (near, far)
    } else {
        (d - g.hough_range_sd_m, d + g.hough_range_sd_m)
    };
    // Nearer than half a metre the frame is far wider than the image.
    (near.max(0.5), far.max(0.5))
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

    /// The robot's pose from the dock in the image alone (at the posts' own heading).
    fn pose_from_dock(g: &DockingGoal, focal_px: f64, centre_u: f64, item: &[f64; 6]) -> Option<Pose2> {
        dock_sight(g, focal_px, centre_u, item).map(|s| s.pose(g, s.heading_rad))
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

    #[test]
    fn the_posts_heading_is_as_uncertain_as_a_pixel_of_post_height_makes_it() {
        let g = goal();
        let sd_deg_at = |x_m: f64| {
            let at = Pose2 { x_m, y_m: 0.0, heading_rad: 0.0 };
            let s = dock_sight(&g, 554.0, 320.0, &seen_from(at, 554.0)).expect("a sight");
            assert!(s.heading_rad.abs() < 1e-9, "{s:?}");
            // The pose at another heading keeps the frame's range and bearing.
            let turned = s.pose(&g, 0.1);
            let back = (g.dock_m[0] - turned.x_m).hypot(g.dock_m[1] - turned.y_m);
            assert!((back - s.ray_m).abs() < 1e-9, "{turned:?} {s:?}");
            s.heading_sd_rad.to_degrees()
        };
        // A pixel on a post 0.5 m tall: about 5 degrees at 4.5 m out, a fifth of that at 2 m.
        let (far, near) = (sd_deg_at(13.6 - 4.5), sd_deg_at(13.6 - 2.0));
        assert!((4.0..6.5).contains(&far), "{far}");
        assert!((0.7..1.5).contains(&near), "{near}");
    }

    #[test]
    fn the_hough_s_scales_span_the_distances_the_ums_s_region_allows() {
        let g = goal();
        let close = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9;
        // No region yet: the paper's four feet either way of the belief.
        assert!(close(hough_band(&g, None, 5.6), (5.6 - 1.22, 5.6 + 1.22)));
        let mut m = harvey_msgs::UncertaintyMap { vertex_count: 4, ..Default::default() };
        for (k, v) in [[7.0, -1.0], [9.0, -1.0], [9.0, 1.0], [7.0, 1.0]].into_iter().enumerate() {
            m.vertices_m[k] = v;
        }
        let region = Region::of(&m).expect("a region");
        // The dock's face at x = 13.6 facing -x: the region lies 4.6-6.6 m from it.
        assert!(close(hough_band(&g, Some(&region), 5.6), (4.3, 6.9)));
        assert!(close(hough_band(&g, Some(&region), 4.0), (3.7, 6.9)), "the belief outside it counts too");
        m.vertices_m[..4].copy_from_slice(&[[13.0, -0.1], [13.3, -0.1], [13.3, 0.1], [13.0, 0.1]]);
        let near = Region::of(&m).expect("a region");
        assert!(close(hough_band(&g, Some(&near), 0.4), (0.5, 0.9)), "never nearer than half a metre");
        m.vertices_m[0] = [f64::INFINITY, 0.0];
        let broken = Region::of(&m).expect("a region");
        assert!(
            close(hough_band(&g, Some(&broken), 5.6), (5.6 - 1.22, 5.6 + 1.22)),
            "not finite: the paper's"
        );
    }
}
