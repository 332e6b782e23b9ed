//! The world as built versus the world as mapped: a robot's map is never exact. `[map_error]`
//! gives the size of the difference, and [`World::as_built`] draws, from a seed, the world the
//! simulator renders and ranges (corners, signs and doors a few centimetres off, paint a little
//! lighter or darker), while the robot's services keep the file as their map.

use harvey_geometry::Rng;
use serde::Deserialize;

use crate::World;

/// Seeds the map error apart from the other draws made from the run's seed.
const STREAM: u64 = 0x6d61_705f_6572_726f;

/// How far the built world differs from its file.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapError {
    /// Standard deviation of each wall corner's offset (x and y) and of each region's shift
    /// along its wall and up it, metres.
    #[serde(default)]
    pub position_sd_m: f64,
    /// Relative standard deviation of each face's and region's reflectance.
    #[serde(default)]
    pub reflectance_sd: f64,
}

/// What the robot knows of its own map and camera (the robot's side of the world file, where
/// `[map_error]` and the camera's imperfections are the simulator's): the map is surveyed to
/// `position_sd_m` (a landmark's own `position_sd_m` where larger), the camera's mount
/// calibrated to `calibration_sd_rad`. Sightings carry these in their spread, so that a map a
/// centimetre off or a mount a few milliradians off widens the UMS's reductions instead of
/// making them exclude the truth.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Survey {
    #[serde(default)]
    pub position_sd_m: f64,
    #[serde(default)]
    pub calibration_sd_rad: f64,
}

impl World {
    /// How well the robot's map places `l`: its own spread, or the survey's where larger.
    pub fn landmark_sd_m(&self, l: &crate::Landmark) -> f64 {
        l.position_sd_m.max(self.survey.position_sd_m)
    }
}

impl MapError {
    pub fn is_none(&self) -> bool {
        self.position_sd_m == 0.0 && self.reflectance_sd == 0.0
    }
}

impl World {
    /// The world as built for a run of `seed`: each distinct wall corner moves by its own
    /// seeded offset (walls meeting there move together, so no gap opens; a corner lying on
    /// another wall moves only along it), each region shifts along and up its wall, and each
    /// reflectance is scaled. Landmarks, locales and doors stay as mapped: they are the robot's
    /// knowledge. With no `[map_error]` the world is returned unchanged.
    pub fn as_built(&self, seed: u64) -> World {
        let mut w = self.clone();
        let e = self.map_error;
        if e.is_none() {
            return w;
        }
        let mut rng = Rng::new(seed ^ STREAM);
        let mut moved: Vec<([f64; 2], [f64; 2])> = Vec::new();
        for i in 0..w.walls.len() {
            for end in 0..2 {
                let p = if end == 0 { self.walls[i].from } else { self.walls[i].to };
                let offset = match moved.iter().find(|(q, _)| *q == p) {
                    Some((_, d)) => *d,
                    None => {
                        let d = [rng.normal(0.0, e.position_sd_m), rng.normal(0.0, e.position_sd_m)];
                        let d = along_host_wall(self, i, p, d);
                        moved.push((p, d));
                        d
                    }
                };
                let q = [p[0] + offset[0], p[1] + offset[1]];
                if end == 0 { w.walls[i].from = q } else { w.walls[i].to = q }
            }
            let wall = &mut w.walls[i];
            wall.reflectance = scaled(wall.reflectance, rng.normal(0.0, e.reflectance_sd));
            for r in &mut wall.regions {
                let (da, dz) = (rng.normal(0.0, e.position_sd_m), rng.normal(0.0, e.position_sd_m));
                r.along_m = r.along_m.map(|a| a + da);
                r.height_m = r.height_m.map(|z| (z + dz).max(0.0));
                r.reflectance = scaled(r.reflectance, rng.normal(0.0, e.reflectance_sd));
            }
        }
        w
    }
}

fn scaled(reflectance: f64, relative: f64) -> f64 {
    (reflectance * (1.0 + relative)).clamp(0.0, 1.0)
}

/// `d` projected on the direction of a wall other than `own` whose inside `p` lies on (a
/// T-junction), so the corner slides along that wall instead of leaving it; else `d`.
fn along_host_wall(world: &World, own: usize, p: [f64; 2], d: [f64; 2]) -> [f64; 2] {
    for (j, w) in world.walls.iter().enumerate() {
        if j == own || w.from == p || w.to == p {
            continue;
        }
        let e = [w.to[0] - w.from[0], w.to[1] - w.from[1]];
        let len = e[0].hypot(e[1]);
        if len < 1e-9 {
            continue;
        }
        let u = [e[0] / len, e[1] / len];
        let rel = [p[0] - w.from[0], p[1] - w.from[1]];
        let t = rel[0] * u[0] + rel[1] * u[1];
        let off = (rel[0] * u[1] - rel[1] * u[0]).abs();
        if off < 1e-6 && t > 0.0 && t < len {
            let k = d[0] * u[0] + d[1] * u[1];
            return [k * u[0], k * u[1]];
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use crate::{MapError, World, load_str};

    fn hallway(error: MapError) -> World {
        let mut w = load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads");
        w.map_error = error;
        w
    }

    #[test]
    fn corners_move_by_the_asked_spread_and_shared_corners_together() {
        let w = hallway(MapError { position_sd_m: 0.02, reflectance_sd: 0.0 });
        let built = w.as_built(7);
        assert_eq!(built, w.as_built(7), "same seed, same building");
        assert_ne!(built, w.as_built(8));
        let mut sq = Vec::new();
        for (a, b) in w.walls.iter().zip(&built.walls) {
            for (p, q) in [(a.from, b.from), (a.to, b.to)] {
                sq.push((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2));
                // Every wall meeting at this corner in the file meets at it as built.
                for (c, d) in w.walls.iter().zip(&built.walls) {
                    if c.from == p {
                        assert_eq!(d.from, q);
                    }
                    if c.to == p {
                        assert_eq!(d.to, q);
                    }
                }
            }
            assert_eq!(a.reflectance, b.reflectance, "no reflectance error asked");
        }
        let rms = (sq.iter().sum::<f64>() / sq.len() as f64).sqrt();
        // Two axes of 2 cm each: 2.8 cm rms for free corners, less where a corner slides.
        assert!(rms > 0.01 && rms < 0.04, "rms corner offset {rms} m");
        assert_eq!(built.landmarks, w.landmarks, "the map's landmarks stay as mapped");
    }

    #[test]
    fn reflectances_scale_and_no_error_changes_nothing() {
        let w = hallway(MapError { position_sd_m: 0.0, reflectance_sd: 0.1 });
        let built = w.as_built(3);
        let changed =
            w.walls.iter().zip(&built.walls).filter(|(a, b)| a.reflectance != b.reflectance).count();
        assert_eq!(changed, w.walls.len());
        assert!(built.walls.iter().all(|b| (0.0..=1.0).contains(&b.reflectance)));
        let exact = hallway(MapError::default());
        assert_eq!(exact.as_built(3), exact);
    }
}
