//! The spatial uncertainty map (002 §3.1) and its growth (§3.3): a convex polygon of possible
//! positions with a most likely centre, and a heading wedge with clockwise and counter-clockwise
//! limits, grown by each turn-and-run with the terrain's Table 3 statistics at `k` sigma.

use std::f64::consts::TAU;

use harvey_world::Terrain;

use crate::geometry::{self, Pt};
use harvey_geometry::FT;

/// Most vertices the published polygon may have (`harvey_msgs::MAX_POLYGON_VERTICES`).
pub const MAX_VERTICES: usize = harvey_msgs::MAX_POLYGON_VERTICES;

/// Position and heading uncertainty.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Map {
    /// Convex, counter-clockwise, world frame; a single point when the pose is known exactly.
    pub polygon: Vec<Pt>,
    pub centre: Pt,
    /// Most likely heading.
    pub heading_rad: f64,
    /// How far the true heading may lie clockwise / counter-clockwise of `heading_rad`.
    pub cw_rad: f64,
    pub ccw_rad: f64,
}

impl Map {
    /// A map that knows the pose exactly (a point and a zero-width wedge).
    pub fn exact(x: f64, y: f64, heading_rad: f64) -> Self {
        Self { polygon: vec![[x, y]], centre: [x, y], heading_rad, cw_rad: 0.0, ccw_rad: 0.0 }
    }

    /// A map starting from a known region (002 §3.3: the start need not be a point).
    pub fn region(polygon: &[Pt], heading_rad: f64, cw_rad: f64, ccw_rad: f64) -> Self {
        let polygon = geometry::hull(polygon);
        let n = polygon.len().max(1) as f64;
        let centre = polygon.iter().fold([0.0, 0.0], |c, p| [c[0] + p[0] / n, c[1] + p[1] / n]);
        Self { polygon, centre, heading_rad, cw_rad, ccw_rad }
    }

    pub fn area_m2(&self) -> f64 {
        geometry::area(&self.polygon)
    }

    /// The heading interval `[lo, hi]` (radians, `lo <= hi`).
    pub fn wedge(&self) -> [f64; 2] {
        [self.heading_rad - self.cw_rad, self.heading_rad + self.ccw_rad]
    }

    /// Whether a pose lies inside the map: position in the polygon, heading in the wedge (a
    /// wedge may reach more than half a turn either way).
    pub fn contains(&self, p: Pt, heading_rad: f64, tol: f64) -> bool {
        let from_cw_limit = (heading_rad - self.heading_rad + self.cw_rad + 1e-12).rem_euclid(TAU);
        geometry::contains(&self.polygon, p, tol) && from_cw_limit <= self.cw_rad + self.ccw_rad + 2e-12
    }

    /// A wedge grown past a full turn says only that the heading is unknown: it is cut back to
    /// one turn, each side in proportion.
    fn limit_wedge(&mut self) {
        let width = self.cw_rad + self.ccw_rad;
        if width > TAU {
            self.cw_rad *= TAU / width;
            self.ccw_rad *= TAU / width;
        }
    }
}

pub use harvey_geometry::wrap;

/// The growth model: Table 3 statistics of the terrain and the probability in sigmas.
#[derive(Debug, Clone)]
pub struct Growth<'t> {
    pub terrain: &'t Terrain,
    pub sigmas: f64,
}

impl Growth<'_> {
    /// A turn of `angle_rad` commanded (counter-clockwise positive), 002 §3.3 and Fig. 71: the
    /// centre turns by the mean, the limits open by `k` deviations on the side the robot may
    /// fall short, and on the other side no further than commanded; skitter moves every point.
    pub fn turn(&self, map: &mut Map, angle_rad: f64) {
        let t = self.terrain;
        let deg = angle_rad.abs().to_degrees();
        if deg == 0.0 {
            return;
        }
        let mean_loss = t.rotational_loss_deg_per_deg * deg;
        let spread = self.sigmas * t.rotational_sd_deg_per_deg * deg;
        map.heading_rad += angle_rad.signum() * (deg - mean_loss).to_radians();
        // Overshooting past the commanded angle is impossible: that side opens by at most the
        // mean loss; the short side by the full spread.
        let (short, long) = (spread.to_radians(), spread.min(mean_loss).to_radians());
        if angle_rad > 0.0 {
            map.cw_rad += short;
            map.ccw_rad += long;
        } else {
            map.ccw_rad += short;
            map.cw_rad += long;
        }
        map.limit_wedge();
        let skitter_m = (t.skitter_ft_per_deg + self.sigmas * t.skitter_sd_ft_per_deg) * deg * FT;
        let pts: Vec<Pt> = map
            .polygon
            .iter()
            .flat_map(|v| {
                [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
                    .map(|[a, b]| [v[0] + a * skitter_m, v[1] + b * skitter_m])
            })
            .collect();
        map.polygon = geometry::limit_vertices(geometry::hull(&pts), MAX_VERTICES);
    }

    /// A run of `distance_m` commanded along the heading (`first` when it starts a MOVE, which
    /// adds the inertial loss once), 002 §3.3 and Fig. 70: each vertex sweeps the sector of
    /// distances and headings it may have travelled, enclosed in a polygon, then the hull.
    pub fn run(&self, map: &mut Map, distance_m: f64, first: bool) {
        let t = self.terrain;
        let ft = distance_m.abs() / FT;
        if ft == 0.0 && !first {
            return;
        }
        let inertial = if first { t.inertial_loss_ft } else { 0.0 };
        let mean_ft = ft - t.translational_loss_ft_per_ft * ft - inertial;
        let spread_ft = self.sigmas * t.translational_sd_ft_per_ft * ft;
        let s_min = (mean_ft - spread_ft).max(0.0) * FT;
        // The inertial loss may not have happened yet part way through a move: it only
        // lowers the near bound.
        let s_max = (mean_ft + inertial + spread_ft).min(ft).max(0.0) * FT;
        // Drift, treated symmetrically (002 §3.2: "by overestimation ... a fixed factor").
        let drift = ((t.drift_deg_per_ft + self.sigmas * t.drift_sd_deg_per_ft) * ft).to_radians();
        let sign = if distance_m < 0.0 { std::f64::consts::PI } else { 0.0 };
        let [lo, hi] = map.wedge();
        let (a0, a1) = (lo - drift / 2.0 + sign, hi + drift / 2.0 + sign);
        let mut pts = Vec::with_capacity(map.polygon.len() * 8);
        for v in &map.polygon {
            pts.push([v[0] + s_min * a0.cos(), v[1] + s_min * a0.sin()]);
            pts.push([v[0] + s_min * a1.cos(), v[1] + s_min * a1.sin()]);
            pts.extend(geometry::arc_enclosure(*v, s_max, a0, a1));
        }
        map.polygon = geometry::limit_vertices(geometry::hull(&pts), MAX_VERTICES);
        let s_mean = mean_ft.max(0.0) * FT;
        map.centre = [
            map.centre[0] + s_mean * (map.heading_rad + sign).cos(),
            map.centre[1] + s_mean * (map.heading_rad + sign).sin(),
        ];
        if !geometry::contains(&map.polygon, map.centre, 1e-9) {
            map.centre = geometry::nearest_point(&map.polygon, map.centre);
        }
        map.cw_rad += drift;
        map.ccw_rad += drift;
        map.limit_wedge();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_from_a_start_region_holds_every_starting_point() {
        let w =
            harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("hallway");
        let g = Growth { terrain: &w.terrain["tile"], sigmas: 3.0 };
        let start = [[0.0, -0.1], [0.2, -0.1], [0.2, 0.1], [0.0, 0.1]];
        let mut map = Map::region(&start, 0.0, 0.02, 0.02);
        assert!((map.area_m2() - 0.04).abs() < 1e-12 && map.centre == [0.1, 0.0]);
        g.turn(&mut map, 0.5);
        g.run(&mut map, 2.0, true);
        // Every start point moved by the mean motion stays inside the grown map.
        let heading = map.heading_rad;
        let s = 2.0 * (1.0 - 0.042) - 0.0084 * 0.3048;
        for p in start {
            let q = [p[0] + s * heading.cos(), p[1] + s * heading.sin()];
            assert!(map.contains(q, heading, 1e-9), "{q:?}");
        }
        assert!(map.area_m2() > 0.04 && map.cw_rad > 0.02 && map.ccw_rad > 0.02);
    }

    #[test]
    fn a_wedge_holds_headings_past_half_a_turn_and_never_grows_past_a_whole_one() {
        let mut map = Map::exact(0.0, 0.0, 0.0);
        (map.cw_rad, map.ccw_rad) = (0.1, 4.0);
        // 3.3 rad counter-clockwise is inside; it wraps to -2.98, which the old test refused.
        assert!(map.contains([0.0, 0.0], 3.3, 1e-9));
        assert!(map.contains([0.0, 0.0], -0.05, 1e-9) && map.contains([0.0, 0.0], 4.0, 1e-9));
        assert!(!map.contains([0.0, 0.0], -0.2, 1e-9) && !map.contains([0.0, 0.0], 4.2, 1e-9));
        let w =
            harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("hallway");
        let g = Growth { terrain: &w.terrain["tile"], sigmas: 3.0 };
        for _ in 0..200 {
            g.run(&mut map, 3.0, false);
            g.turn(&mut map, 1.5);
        }
        assert!((map.cw_rad + map.ccw_rad - TAU).abs() < 1e-9, "{} {}", map.cw_rad, map.ccw_rad);
        let centre = map.centre;
        assert!((-40..=40).all(|k| map.contains(centre, f64::from(k) * 0.1, 1e-9)), "every heading");
    }
}
