//! The world's data: what the file holds, in SI units.

use serde::Deserialize;

/// A planar pose in the world frame.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pose {
    pub x_m: f64,
    pub y_m: f64,
    pub heading_deg: f64,
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
}

/// A vertical planar face standing on the floor, from `from` to `to`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub height_m: f64,
    pub reflectance: f64,
    #[serde(default, rename = "region")]
    pub regions: Vec<Region>,
}

impl Wall {
    pub fn length_m(&self) -> f64 {
        (self.to[0] - self.from[0]).hypot(self.to[1] - self.from[1])
    }

    /// Reflectance at `along_m` from `from`, `z_m` above the floor: the last region containing
    /// the point wins, else the wall's own.
    pub fn reflectance_at(&self, along_m: f64, z_m: f64) -> f64 {
        self.regions
            .iter()
            .rev()
            .find(|r| {
                (r.along_m[0]..=r.along_m[1]).contains(&along_m)
                    && (r.height_m[0]..=r.height_m[1]).contains(&z_m)
            })
            .map_or(self.reflectance, |r| r.reflectance)
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
}

/// A whole world.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    pub name: String,
    /// The terrain the robot drives on, a key of `terrain`.
    pub ground: String,
    pub start: Pose,
    pub robot: Robot,
    pub camera: Camera,
    pub floor: Floor,
    pub terrain: std::collections::BTreeMap<String, Terrain>,
    #[serde(rename = "wall")]
    pub walls: Vec<Wall>,
}

impl World {
    /// The statistics of the terrain the robot is on.
    pub fn ground_terrain(&self) -> &Terrain {
        // `load_str` rejects worlds whose ground is not in the table.
        &self.terrain[&self.ground]
    }
}
