//! Ray casting against the walls, for the sonar model and the camera renderer.

use crate::World;

/// Where a ray meets a wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub distance_m: f64,
    pub wall: usize,
    /// Distance along the wall from its `from` end.
    pub along_m: f64,
    /// Angle between the ray and the wall's normal, 0 = head-on, π/2 = grazing.
    pub incidence_rad: f64,
}

impl World {
    /// The nearest wall hit by the ray from `origin` along unit direction `dir`, within `max_m`.
    pub fn cast_ray(&self, origin: [f64; 2], dir: [f64; 2], max_m: f64) -> Option<Hit> {
        self.ray_hits(origin, dir, max_m).min_by(|a, b| a.distance_m.total_cmp(&b.distance_m))
    }

    /// Every wall the ray meets within `max_m`, in the walls' order.
    pub fn ray_hits(&self, origin: [f64; 2], dir: [f64; 2], max_m: f64) -> impl Iterator<Item = Hit> + '_ {
        self.walls.iter().enumerate().filter_map(move |(i, w)| hit(i, w, origin, dir, max_m))
    }

    /// Every wall the ray meets within `max_m`, nearest first, into `out` (cleared first): what
    /// a ray passing over a wall lower than itself meets next.
    pub fn cast_ray_all(&self, origin: [f64; 2], dir: [f64; 2], max_m: f64, out: &mut Vec<Hit>) {
        out.clear();
        out.extend(self.ray_hits(origin, dir, max_m));
        out.sort_by(|a, b| a.distance_m.total_cmp(&b.distance_m).then(a.wall.cmp(&b.wall)));
    }
}

/// Where the ray meets wall `i`, if it does within `max_m`.
fn hit(i: usize, w: &crate::Wall, origin: [f64; 2], dir: [f64; 2], max_m: f64) -> Option<Hit> {
    let e = [w.to[0] - w.from[0], w.to[1] - w.from[1]];
    let denom = dir[0] * e[1] - dir[1] * e[0];
    if denom.abs() < 1e-12 {
        return None; // parallel
    }
    let d = [w.from[0] - origin[0], w.from[1] - origin[1]];
    let t = (d[0] * e[1] - d[1] * e[0]) / denom; // along the ray
    let s = (d[0] * dir[1] - d[1] * dir[0]) / denom; // along the wall, 0..1
    if t <= 1e-9 || !(0.0..=1.0).contains(&s) || t > max_m {
        return None;
    }
    let len = e[0].hypot(e[1]);
    let cos_inc = (denom / len).abs(); // |dir x e| / |e| = |cos| of angle to normal
    Some(Hit { distance_m: t, wall: i, along_m: s * len, incidence_rad: cos_inc.clamp(0.0, 1.0).acos() })
}

#[cfg(test)]
mod tests {
    use crate::load_str;

    #[test]
    fn rays_hit_the_nearest_wall_with_the_right_incidence() {
        let w = load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads");
        // Straight across the corridor from its centre line: head-on.
        let hit = w.cast_ray([2.0, 0.0], [0.0, 1.0], 100.0).expect("hits the left wall");
        assert!((hit.distance_m - 1.0).abs() < 1e-9, "{hit:?}");
        assert!(hit.incidence_rad.abs() < 1e-9);
        // At 60 degrees off the normal the distance is 1 / cos 60 = 2.
        let a = 30f64.to_radians();
        let hit = w.cast_ray([2.0, 0.0], [a.cos(), a.sin()], 100.0).expect("hits");
        assert!((hit.distance_m - 2.0).abs() < 1e-9, "{hit:?}");
        assert!((hit.incidence_rad - 60f64.to_radians()).abs() < 1e-9);
        assert!(w.cast_ray([2.0, 0.0], [0.0, 1.0], 0.5).is_none(), "beyond max range");
    }

    #[test]
    fn every_wall_on_the_ray_comes_nearest_first() {
        let w = load_str(include_str!("../../../worlds/room.toml"), "room").expect("loads");
        // From the start towards the goal: the box's near and far faces, then the east wall.
        let mut hits = Vec::new();
        w.cast_ray_all([w.start.x_m, w.start.y_m], [1.0, 0.0], 100.0, &mut hits);
        let at: Vec<(f64, f64)> = hits.iter().map(|h| (h.distance_m, w.walls[h.wall].height_m)).collect();
        let expect = [(2.2, 0.8), (2.8, 0.8), (7.2, 2.6)];
        assert_eq!(at.len(), expect.len(), "{at:?}");
        for ((d, h), (ed, eh)) in at.iter().zip(expect) {
            assert!((d - ed).abs() < 1e-9 && (h - eh).abs() < 1e-9, "{at:?}");
        }
        assert_eq!(w.cast_ray([w.start.x_m, w.start.y_m], [1.0, 0.0], 100.0), Some(hits[0]));
    }
}
