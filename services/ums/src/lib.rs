//! The UMS's logic, first version: the position uncertainty grows with the distance and
//! rotation reported by odometry, at 3 sigma of the terrain's Table 3 statistics (002 §3.2), as a
//! rectangle aligned with the heading plus a heading wedge. The paper's convex-hull growth and the
//! landmark reductions come with the UMS issue.

pub mod expecter;
pub mod geometry;
pub mod map;
pub mod reduction;

use harvey_msgs::{Header, MAX_POLYGON_VERTICES, Odometry, Pose2, UncertaintyMap};
use harvey_world::Terrain;

const FT: f64 = 0.3048;
/// Sigmas of the map's probability (002 §3.1 uses 2 or 3).
const SIGMAS: f64 = 3.0;

/// Accumulated motion since the map was last a point.
#[derive(Debug)]
pub struct Ums {
    terrain: Terrain,
    last: Option<Pose2>,
    travelled_m: f64,
    turned_rad: f64,
    seq: u64,
}

impl Ums {
    pub fn new(terrain: Terrain) -> Self {
        Self { terrain, last: None, travelled_m: 0.0, turned_rad: 0.0, seq: 0 }
    }

    /// Grows the map by the motion since the previous odometry; returns the map to publish.
    pub fn on_odometry(&mut self, o: &Odometry) -> Result<UncertaintyMap, String> {
        let p = o.world_from_robot;
        if !(p.x_m.is_finite() && p.y_m.is_finite() && p.heading_rad.is_finite()) {
            return Err("odometry holds a non-finite pose".into());
        }
        if let Some(q) = self.last {
            self.travelled_m += (p.x_m - q.x_m).hypot(p.y_m - q.y_m);
            let d = (p.heading_rad - q.heading_rad + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            self.turned_rad += d.abs();
        }
        self.last = Some(p);
        let t = &self.terrain;
        let ft = self.travelled_m / FT;
        let deg = self.turned_rad.to_degrees();
        let along_m =
            SIGMAS * t.translational_sd_ft_per_ft * ft * FT + t.inertial_loss_ft * FT * f64::from(ft > 0.0);
        let drift_rad = (SIGMAS * t.drift_sd_deg_per_ft * ft).to_radians();
        let cross_m =
            self.travelled_m * (drift_rad / 2.0).sin() + SIGMAS * t.skitter_sd_ft_per_deg * deg * FT;
        let wedge_rad = drift_rad + (SIGMAS * t.rotational_sd_deg_per_deg * deg).to_radians();
        let (c, s) = (p.heading_rad.cos(), p.heading_rad.sin());
        let mut vertices_m = [[0.0; 2]; MAX_POLYGON_VERTICES];
        for (v, (a, b)) in vertices_m.iter_mut().zip([(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)]) {
            let (dx, dy) = (a * along_m, b * cross_m);
            *v = [p.x_m + dx * c - dy * s, p.y_m + dx * s + dy * c];
        }
        self.seq += 1;
        Ok(UncertaintyMap {
            header: Header::new(self.seq, o.header.stamp_ns),
            centre: p,
            vertex_count: 4,
            reserved: 0,
            vertices_m,
            heading_cw_rad: p.heading_rad - wedge_rad,
            heading_ccw_rad: p.heading_rad + wedge_rad,
            area_m2: 4.0 * along_m * cross_m,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tile, from the hallway world's copy of 002 Table 3.
    fn tile() -> Terrain {
        let world = include_str!("../../../worlds/hallway.toml");
        harvey_world::load_str(world, "hallway.toml").expect("hallway loads").terrain["tile"].clone()
    }

    fn odo(x_m: f64) -> Odometry {
        Odometry { world_from_robot: Pose2 { x_m, y_m: 0.0, heading_rad: 0.0 }, ..Default::default() }
    }

    #[test]
    fn the_map_grows_with_distance_and_contains_the_pose() {
        let mut u = Ums::new(tile());
        let start = u.on_odometry(&odo(0.0)).expect("ok");
        assert_eq!(start.area_m2, 0.0);
        let mut last_area = 0.0;
        for i in 1..=10 {
            let m = u.on_odometry(&odo(i as f64)).expect("ok");
            assert!(m.area_m2 > last_area, "area must grow");
            last_area = m.area_m2;
            let xs: Vec<f64> = m.vertices_m[..4].iter().map(|v| v[0]).collect();
            assert!(xs.iter().any(|&x| x > i as f64) && xs.iter().any(|&x| x < i as f64));
        }
        // 10 m = 32.8 ft: along-track half-size 3 x 0.0028 x 32.8 ft plus the inertial loss.
        let m = u.on_odometry(&odo(10.0)).expect("ok");
        let along = (m.vertices_m[0][0] - 10.0) / FT;
        assert!((along - (3.0 * 0.0028 * 10.0 / FT + 0.0084)).abs() < 1e-9, "{along}");
        assert!(u.on_odometry(&odo(f64::NAN)).is_err());
    }
}
