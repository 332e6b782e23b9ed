//! Whether an uncertainty map holds a pose: the check of the UMS's promise against the truth
//! (`harvey run`'s summary, the sweep's figures, the tests).

use crate::{MAX_POLYGON_VERTICES, Pose2, UncertaintyMap};

impl UncertaintyMap {
    /// Whether the pose lies inside the map, within `tol_m` of each edge's line of the convex
    /// polygon (of a point or a segment while the map has fewer than three vertices) and within
    /// the heading wedge (to 1e-9 rad either side): the promise the UMS's `k`-sigma growth and
    /// reductions make about the true pose.
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
        const EPS: f64 = 1e-9;
        let d = harvey_geometry::wrap(p.heading_rad - self.centre.heading_rad);
        let width = self.heading_cw_rad + self.heading_ccw_rad;
        // A wedge of a whole turn holds every heading; otherwise the heading's angle
        // counter-clockwise from the wedge's clockwise limit (less a hair, so that a heading a
        // rounding past that limit is not taken a whole turn round) must not pass its width.
        let from_cw = (d + self.heading_cw_rad + EPS).rem_euclid(std::f64::consts::TAU);
        inside && (width >= std::f64::consts::TAU - EPS || from_cw <= width + 2.0 * EPS)
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
    fn a_wedge_holds_its_headings_round_the_wrap_and_past_half_a_turn_on_one_side() {
        let at = |heading: f64, cw: f64, ccw: f64| UncertaintyMap {
            centre: Pose2 { x_m: 0.5, y_m: 0.5, heading_rad: heading },
            ..square(cw, ccw)
        };
        // One side longer than half a turn: -3.0 rad is 3.28 rad counter-clockwise of 0, inside
        // 3.5; -0.2 is clockwise past 0.1.
        let lopsided = at(0.0, 0.1, 3.5);
        assert!(lopsided.holds(&pose(0.5, 0.5, -3.0), 1e-6) && !lopsided.holds(&pose(0.5, 0.5, -0.2), 1e-6));
        // Round the wrap: centred at 3.1 rad, -3.1 is 0.083 rad counter-clockwise of it.
        let wrapped = at(3.1, 0.1, 0.1);
        assert!(wrapped.holds(&pose(0.5, 0.5, -3.1), 1e-6) && !wrapped.holds(&pose(0.5, 0.5, -2.9), 1e-6));
        // Exactly at either limit, however the subtraction rounds; a zero-width wedge holds its
        // own heading.
        for c in [0.3, -2.7, 3.0, 1.234_567] {
            let m = at(c, 0.07, 0.05);
            assert!(
                m.holds(&pose(0.5, 0.5, c - 0.07), 1e-6) && m.holds(&pose(0.5, 0.5, c + 0.05), 1e-6),
                "{c}"
            );
            assert!(
                !m.holds(&pose(0.5, 0.5, c - 0.0701), 1e-6) && !m.holds(&pose(0.5, 0.5, c + 0.0501), 1e-6)
            );
            assert!(at(c, 0.0, 0.0).holds(&pose(0.5, 0.5, c), 1e-6), "{c}");
        }
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
