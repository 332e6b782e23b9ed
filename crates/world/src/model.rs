//! The world's data: what the file holds, in SI units.

pub use harvey_geometry::Pose2;
use serde::Deserialize;

use crate::topology::{Door, Landmark, Locale, Meadow, contains, signed_area};

fn white() -> [f64; 3] {
    [1.0, 1.0, 1.0]
}

/// The start pose as a world file gives it: `[start] x_m, y_m, heading_deg`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct StartPose {
    x_m: f64,
    y_m: f64,
    heading_deg: f64,
}

/// Reads `[start]` (heading in degrees) into the one pose type.
fn start_pose<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Pose2, D::Error> {
    let p = StartPose::deserialize(d)?;
    Ok(Pose2::from_degrees(p.x_m, p.y_m, p.heading_deg))
}

/// A rectangle on a wall with its own reflectance (a door, a sign, a baseboard).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    /// Along the wall from its `from` end.
    pub along_m: [f64; 2],
    /// Height above the floor.
    pub height_m: [f64; 2],
    pub reflectance: f64,
    /// Relative colour (red, green, blue in 0..=1) multiplying the reflectance in colour images.
    #[serde(default = "white")]
    pub colour: [f64; 3],
}

/// A vertical planar face standing on the floor, from `from` to `to`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub height_m: f64,
    pub reflectance: f64,
    #[serde(default = "white")]
    pub colour: [f64; 3],
    #[serde(default, rename = "region")]
    pub regions: Vec<Region>,
}

impl Wall {
    pub fn length_m(&self) -> f64 {
        (self.to[0] - self.from[0]).hypot(self.to[1] - self.from[1])
    }

    /// Reflectance and colour at `along_m` from `from`, `z_m` above the floor: the last region
    /// containing the point wins, else the wall's own.
    pub fn appearance_at(&self, along_m: f64, z_m: f64) -> (f64, [f64; 3]) {
        self.regions
            .iter()
            .rev()
            .find(|r| {
                (r.along_m[0]..=r.along_m[1]).contains(&along_m)
                    && (r.height_m[0]..=r.height_m[1]).contains(&z_m)
            })
            .map_or((self.reflectance, self.colour), |r| (r.reflectance, r.colour))
    }

    /// Reflectance at `along_m` from `from`, `z_m` above the floor.
    pub fn reflectance_at(&self, along_m: f64, z_m: f64) -> f64 {
        self.appearance_at(along_m, z_m).0
    }
}

/// Floor tiles in a checkerboard of two reflectances.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Floor {
    pub tile_m: f64,
    pub reflectance: [f64; 2],
    pub ceiling_reflectance: f64,
}

/// Error statistics of one terrain (002 §3.2, Table 3), per foot or degree as the paper gives.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Terrain {
    pub translational_loss_ft_per_ft: f64,
    pub inertial_loss_ft: f64,
    pub translational_sd_ft_per_ft: f64,
    pub drift_deg_per_ft: f64,
    pub drift_sd_deg_per_ft: f64,
    pub rotational_loss_deg_per_deg: f64,
    pub rotational_sd_deg_per_deg: f64,
    pub skitter_ft_per_deg: f64,
    pub skitter_sd_ft_per_deg: f64,
}

/// The vehicle: drive speeds and the sonar ring.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Robot {
    pub speed_mps: f64,
    pub turn_rate_degps: f64,
    pub sonar_ring_radius_m: f64,
    pub sonar_beam_width_deg: f64,
    /// Beyond this angle between the beam and the wall's normal the echo reflects away.
    pub sonar_specular_limit_deg: f64,
    pub sonar_max_range_ft: f64,
    /// Range noise of an echo, standard deviation in feet (seeded).
    #[serde(default)]
    pub sonar_range_sd_ft: f64,
    /// Chance that a sensor hears nothing although an echo came back (seeded).
    #[serde(default)]
    pub sonar_dropout: f64,
    /// Chance that a sensor hears the echo of another sensor of its bank, fired at the same time,
    /// and reports that range when it is the shorter (001 §3: crosstalk).
    #[serde(default)]
    pub sonar_crosstalk: f64,
    /// Chance that the echo comes back by way of a second wall: a range 20-100 % too long
    /// (001 §3: multiple reflections).
    #[serde(default)]
    pub sonar_multipath: f64,
    /// Shaft-encoder resolution of travel, feet per count (0: exact).
    #[serde(default)]
    pub encoder_count_ft: f64,
    /// Shaft-encoder resolution of the steering, degrees per count (0: exact).
    #[serde(default)]
    pub encoder_count_deg: f64,
}

/// The pinhole camera on the robot, looking along its heading.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub width_px: u32,
    pub height_px: u32,
    pub focal_px: f64,
    pub height_m: f64,
    /// Scene illumination: a pixel is `illumination x reflectance`, clamped to 255.
    pub illumination: f64,
    /// Uneven lighting: the image corners receive `1 - vignetting` of the centre's light.
    #[serde(default)]
    pub vignetting: f64,
    /// Sensor noise, standard deviation in grey levels (seeded per frame).
    #[serde(default)]
    pub noise_sd: f64,
    /// The light's slow change over a run (clouds, lights): the illumination swings by this
    /// fraction either way, sinusoidally over `illumination_period_s`, at a seeded phase.
    #[serde(default)]
    pub illumination_drift: f64,
    #[serde(default = "default_illumination_period_s")]
    pub illumination_period_s: f64,
    /// The mount's misalignment that the robot's calibration does not know: the true yaw and
    /// pitch of the camera are drawn per run from a normal of this standard deviation, radians
    /// (000 §5.5 Fig. 10 studies 0.001 and 0.010 rad).
    #[serde(default)]
    pub misalignment_sd_rad: f64,
    /// For an experiment, the mount's true yaw (left +) and pitch (down +) exactly, rad, not drawn
    /// (000 §5.5 Fig. 10; `conditions/mount-*.toml`); unknown to the robot too.
    #[serde(default)]
    pub mount_error_rad: Option<[f64; 2]>,
    /// Optical blur: a box filter of this radius in pixels (0: sharp).
    #[serde(default)]
    pub blur_px: u32,
    /// A stereo pair (003): the distance between the two cameras, the left one half of it left
    /// of the robot's centre line, the right one as far right; both as this camera, on one
    /// mount. `None`: a single camera at the centre.
    #[serde(default)]
    pub stereo_baseline_m: Option<f64>,
}

fn default_illumination_period_s() -> f64 {
    120.0
}

/// A whole world.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    pub name: String,
    /// The terrain the robot drives on, a key of `terrain`.
    pub ground: String,
    #[serde(deserialize_with = "start_pose")]
    pub start: Pose2,
    pub robot: Robot,
    pub camera: Camera,
    pub floor: Floor,
    pub terrain: std::collections::BTreeMap<String, Terrain>,
    #[serde(rename = "wall")]
    pub walls: Vec<Wall>,
    #[serde(default, rename = "locale")]
    pub locales: Vec<Locale>,
    #[serde(default, rename = "door")]
    pub doors: Vec<Door>,
    #[serde(default, rename = "meadow")]
    pub meadows: Vec<Meadow>,
    #[serde(default, rename = "landmark")]
    pub landmarks: Vec<Landmark>,
    /// Coded poles to put down at seeded places (`poles.rs`, 004 §5).
    #[serde(default)]
    pub poles: Option<crate::PoleField>,
    /// How far the world as built differs from this file, the robot's map (`as_built.rs`).
    #[serde(default)]
    pub map_error: crate::MapError,
    /// What the robot knows of its map's and camera's accuracy (`as_built.rs`).
    #[serde(default)]
    pub survey: crate::Survey,
    /// Moving things (`movers.rs`), added from a mission; their walls follow `static_walls`.
    #[serde(skip)]
    pub(crate) movers: Vec<crate::Mover>,
    #[serde(skip)]
    pub(crate) static_walls: usize,
    /// Round pillars put down (the poles): drawn as eight walls each, echoing as cylinders.
    #[serde(skip)]
    pub(crate) pillars: Vec<crate::Pillar>,
}

impl World {
    /// The statistics of the world's default terrain (where no meadow says otherwise).
    pub fn ground_terrain(&self) -> &Terrain {
        // `load_str` rejects worlds whose ground is not in the table.
        &self.terrain[&self.ground]
    }

    /// The meadow containing `(x, y)`, if any.
    pub fn meadow_at(&self, x: f64, y: f64) -> Option<&Meadow> {
        self.meadows.iter().find(|m| contains(&m.outline, [x, y]))
    }

    /// The terrain under `(x, y)`: its meadow's, else the world's ground.
    pub fn terrain_at(&self, x: f64, y: f64) -> &Terrain {
        // `load_str` rejects meadows whose terrain is not in the table.
        self.meadow_at(x, y).map_or(self.ground_terrain(), |m| &self.terrain[&m.terrain])
    }

    /// The diagonal of the walls' bounding box (m): nothing in the world is seen further away.
    pub fn diagonal_m(&self) -> f64 {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in self.walls.iter().flat_map(|w| [w.from, w.to]) {
            for k in 0..2 {
                (lo[k], hi[k]) = (lo[k].min(p[k]), hi[k].max(p[k]));
            }
        }
        if lo[0] > hi[0] { 0.0 } else { (hi[0] - lo[0]).hypot(hi[1] - lo[1]) }
    }

    /// The reflectances of the floor's checker pattern at `(x, y)`.
    pub fn floor_reflectance_at(&self, x: f64, y: f64) -> [f64; 2] {
        self.meadows
            .iter()
            .filter_map(|m| m.floor_reflectance.map(|r| (m, r)))
            .find(|(m, _)| contains(&m.outline, [x, y]))
            .map_or(self.floor.reflectance, |(_, r)| r)
    }

    /// The centre (vertex mean) of the first meadow of `terrain`, if any: a place to stand on it.
    pub fn meadow_centre(&self, terrain: &str) -> Option<[f64; 2]> {
        let m = self.meadows.iter().find(|m| m.terrain == terrain)?;
        let n = m.outline.len() as f64;
        Some(m.outline.iter().fold([0.0, 0.0], |c, p| [c[0] + p[0] / n, c[1] + p[1] / n]))
    }

    /// Moves the start to the centre of a meadow of `terrain` (for experiments on one terrain);
    /// false when no meadow has it.
    pub fn start_on_terrain(&mut self, terrain: &str) -> bool {
        match self.meadow_centre(terrain) {
            Some([x, y]) if self.meadow_at(x, y).is_some_and(|m| m.terrain == terrain) => {
                (self.start.x_m, self.start.y_m) = (x, y);
                true
            }
            _ => false,
        }
    }

    /// The innermost locale whose outline contains `(x, y)`.
    pub fn locale_at(&self, x: f64, y: f64) -> Option<&Locale> {
        self.locales
            .iter()
            .filter(|l| l.outline.len() >= 3 && contains(&l.outline, [x, y]))
            .min_by(|a, b| signed_area(&a.outline).abs().total_cmp(&signed_area(&b.outline).abs()))
    }

    pub fn landmark(&self, name: &str) -> Option<&Landmark> {
        self.landmarks.iter().find(|l| l.name == name)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_start_heading_is_read_in_degrees() {
        // worlds/arena.toml: `[start] heading_deg = 45.0`.
        let w = crate::load_str(include_str!("../../../worlds/arena.toml"), "arena.toml").expect("loads");
        assert_eq!(w.start.heading_rad, 45f64.to_radians());
    }
}
