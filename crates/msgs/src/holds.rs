//! Whether an uncertainty map holds a pose: the check of the UMS's promise against the truth
//! (`harvey run`'s summary, the sweep's figures, the tests).

use crate::{MAX_POLYGON_VERTICES, Pose2, UncertaintyMap};

impl UncertaintyMap {
    /// Whether the pose lies inside the map, within `tol_m` of the polygon (a point or a segment
    /// while the map has fewer than three vertices) and within the heading wedge: the promise the
    /// UMS's `k`-sigma growth and reductions make about the true pose.
    pub fn holds(&self, p: &Pose2, tol_m: f64) -> bool {
        let v = &self.vertices_m[..(self.vertex_count as usize).min(MAX_POLYGON_VERTICES)];
        let at = [p.x_m, p.y_m];
        let inside = match v {
            [] => false,
            [a] => (a[0] - at[0]).hypot(a[1] - at[1]) <= tol_m,
            [a, b] => harvey_geometry::distance_to_segment(*a, *b, at) <= tol_m,
            _ => (0..v.len()).all(|i| {
                let (a, b) = (v[i], v[(i + 1) % v.len()]);
                let cross = (b[0] - a[0]) * (at[1] - a[1]) - (b[1] - a[1]) * (at[0] - a[0]);
                cross / (b[0] - a[0]).hypot(b[1] - a[1]).max(1e-300) >= -tol_m
            }),
        };
        let d = harvey_geometry::wrap(p.heading_rad - self.centre.heading_rad);
        // A wedge wider than half a turn either way holds every heading it reaches round to.
        let wide = self.heading_cw_rad + self.heading_ccw_rad >= std::f64::consts::TAU - 1e-9;
        let from_cw = (d + self.heading_cw_rad).rem_euclid(std::f64::consts::TAU);
        inside && (wide || from_cw <= self.heading_cw_rad + self.heading_ccw_rad + 1e-9)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(cw: f64, ccw: f64) -> UncertaintyMap {
        let mut m = UncertaintyMap {
            vertex_count: 4,
            heading_cw_rad: cw,
            heading_ccw_rad: ccw,
            ..Default::default()
        };
        m.vertices_m[..4].copy_from_slice(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
        m
    }

    fn pose(x_m: f64, y_m: f64, heading_rad: f64) -> Pose2 {
        Pose2 { x_m, y_m, heading_rad }
    }

    #[test]
    fn a_pose_is_held_inside_the_polygon_and_the_wedge_only() {
        let m = square(0.1, 0.2);
        assert!(m.holds(&pose(0.5, 0.5, 0.0), 1e-6));
        assert!(m.holds(&pose(1.0, 0.5, -0.1), 1e-6) && m.holds(&pose(0.0, 0.0, 0.2), 1e-6));
        assert!(!m.holds(&pose(1.001, 0.5, 0.0), 1e-6) && m.holds(&pose(1.001, 0.5, 0.0), 0.002));
        assert!(!m.holds(&pose(0.5, 0.5, -0.11), 1e-6) && !m.holds(&pose(0.5, 0.5, 0.21), 1e-6));
        // Round the far side of the turn: still outside a narrow wedge.
        assert!(!m.holds(&pose(0.5, 0.5, std::f64::consts::PI), 1e-6));
        let full = square(3.2, 3.2);
        assert!(full.holds(&pose(0.5, 0.5, std::f64::consts::PI), 1e-6));
    }

    #[test]
    fn a_map_of_a_point_or_a_segment_holds_only_what_lies_within_the_tolerance() {
        let mut m = UncertaintyMap { vertex_count: 1, ..Default::default() };
        m.vertices_m[0] = [2.0, 3.0];
        assert!(m.holds(&pose(2.0, 3.0, 0.0), 1e-6) && !m.holds(&pose(2.01, 3.0, 0.0), 1e-6));
        m.vertex_count = 2;
        m.vertices_m[1] = [4.0, 3.0];
        assert!(m.holds(&pose(3.0, 3.0, 0.0), 1e-6) && !m.holds(&pose(3.0, 3.01, 0.0), 1e-6));
        m.vertex_count = 0;
        assert!(!m.holds(&pose(2.0, 3.0, 0.0), 1e-6));
    }
}
