//! Harvey's world model: planar walls with reflectance regions, the floor, terrain error
//! statistics, the robot's sonar and drive, and the camera; loaded from TOML and ray cast.
//!

mod as_built;
mod bounds;
mod bounds_topology;
mod camera;
mod check;
mod ground_line;
mod load;
mod model;
mod movers;
mod poles;
mod raycast;
pub mod selection;
pub mod topology;

pub use as_built::{MapError, Survey};
pub use camera::project_with;
pub use check::Inconsistency;
pub use load::{WorldError, load_str};
pub use model::*;
pub use movers::{Mover, load_movers, parse_movers};
pub use poles::{Pillar, Pole, PoleError, PoleField};
pub use raycast::Hit;
pub use topology::{Door, Landmark, LandmarkClass, Locale, Meadow, Strategy};

impl World {
    /// Loads a world file; errors name the file, line and field.
    pub fn load(path: &std::path::Path) -> Result<World, WorldError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| WorldError::Io { file: path.display().to_string(), detail: e.to_string() })?;
        load_str(&text, &path.display().to_string())
    }
}
