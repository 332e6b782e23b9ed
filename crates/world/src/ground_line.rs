//! Where a class III landmark's edge runs along a wall's foot: the lowest band painted from the
//! floor (a baseboard), whose top is what a camera sees of the line.

use crate::{Landmark, LandmarkClass, Region, Wall, World};

impl World {
    /// The wall the class III landmark `l` runs along and overlaps (the first: a line past
    /// doorways runs along several) and its lowest band standing on the floor below the camera;
    /// `None` for a line along no such wall (a floor edge).
    pub fn wall_band(&self, l: &Landmark) -> Option<(&Wall, &Region)> {
        let (LandmarkClass::III, Some(to)) = (l.class, l.to_m) else { return None };
        let a = l.position_m;
        self.walls.iter().find_map(|w| {
            let len = w.length_m();
            let along = |p: [f64; 3]| w.local([p[0], p[1]]).0;
            let on = |p: [f64; 3]| w.local([p[0], p[1]]).1.abs() < 0.02;
            let (lo, hi) = (along(a).min(along(to)), along(a).max(along(to)));
            if !(on(a) && on(to)) || hi <= 0.0 || lo >= len {
                return None;
            }
            let r = w
                .regions
                .iter()
                .filter(|r| r.height_m[0] <= 0.0 && r.height_m[1] < self.camera.height_m)
                .min_by(|p, q| p.height_m[1].total_cmp(&q.height_m[1]))?;
            Some((w, r))
        })
    }
}
