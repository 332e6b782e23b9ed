//! Where the UMS says the robot can be (its `ums/map`: a convex polygon and a heading wedge),
//! as a gate on a pose fix the behaviour has no fix of its own to judge by: a first pose from the
//! dock that lies outside the region (by more than the fix's own error) is a misreading, however
//! sure the Hough was of the dock (002 §5: the UMS bounds what a sighting may say).

use harvey_geometry::{distance_to_segment, wrap};
use harvey_msgs::{Pose2, UncertaintyMap};

/// The UMS's region, as last published.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    polygon: Vec<[f64; 2]>,
    heading_rad: f64,
    cw_rad: f64,
    ccw_rad: f64,
}

impl Region {
    /// The map's region; `None` for a map without a polygon.
    pub fn of(m: &UncertaintyMap) -> Option<Self> {
        let n = (m.vertex_count as usize).min(m.vertices_m.len());
        (n >= 3).then(|| Self {
            polygon: m.vertices_m[..n].to_vec(),
            heading_rad: m.centre.heading_rad,
            cw_rad: m.heading_cw_rad,
            ccw_rad: m.heading_ccw_rad,
        })
    }

    /// Whether `p` lies in the region, give or take `margin_m` of position and `margin_rad` of
    /// heading (the fix's own error).
    pub fn admits(&self, p: &Pose2, margin_m: f64, margin_rad: f64) -> bool {
        let at = [p.x_m, p.y_m];
        let inside = harvey_world::topology::contains(&self.polygon, at)
            || (0..self.polygon.len()).any(|k| {
                distance_to_segment(self.polygon[k], self.polygon[(k + 1) % self.polygon.len()], at)
                    <= margin_m
            });
        let off = wrap(p.heading_rad - self.heading_rad);
        inside && (-self.cw_rad - margin_rad..=self.ccw_rad + margin_rad).contains(&off)
    }

    /// The least and greatest of `f` over the region (a linear `f`'s extremes over a convex
    /// polygon are at its vertices).
    pub fn span(&self, f: impl Fn([f64; 2]) -> f64) -> (f64, f64) {
        let values = self.polygon.iter().map(|&v| f(v));
        values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map() -> UncertaintyMap {
        let mut m = UncertaintyMap {
            centre: Pose2 { x_m: 8.0, y_m: 0.0, heading_rad: 0.0 },
            vertex_count: 4,
            heading_cw_rad: 0.2,
            heading_ccw_rad: 0.3,
            ..Default::default()
        };
        for (k, v) in [[7.0, -1.0], [9.0, -1.0], [9.0, 1.0], [7.0, 1.0]].into_iter().enumerate() {
            m.vertices_m[k] = v;
        }
        m
    }

    #[test]
    fn a_fix_inside_the_region_or_within_its_error_of_it_is_admitted() {
        let r = Region::of(&map()).expect("a region");
        let pose = |x_m, y_m, deg: f64| Pose2 { x_m, y_m, heading_rad: deg.to_radians() };
        assert!(r.admits(&pose(8.5, 0.5, 5.0), 0.3, 0.1));
        assert!(r.admits(&pose(9.25, 0.0, 0.0), 0.3, 0.1), "a quarter metre out, within the fix's error");
        assert!(!r.admits(&pose(9.5, 0.0, 0.0), 0.3, 0.1));
        // dim seed 3's misreading: 3.5 m and 34 degrees from where the robot was.
        assert!(!r.admits(&pose(10.07, -3.82, 33.4), 0.3, 0.14));
        assert!(r.admits(&pose(8.0, 0.0, -17.0), 0.0, 0.1), "clockwise within the wedge and its margin");
        assert!(!r.admits(&pose(8.0, 0.0, -20.0), 0.0, 0.1));
        assert!(r.admits(&pose(8.0, 0.0, 22.0), 0.0, 0.1));
        assert!(!r.admits(&pose(8.0, 0.0, 25.0), 0.0, 0.1));
        assert_eq!(Region::of(&UncertaintyMap::default()), None, "no polygon, no region");
        assert_eq!(r.span(|p| p[0] - 10.0), (-3.0, -1.0));
        assert_eq!(r.span(|p| 0.5 * p[1]), (-0.5, 0.5));
    }
}
