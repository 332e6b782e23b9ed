//! Harvey's world model: planar walls with reflectance regions, the floor, terrain error
//! statistics, the robot's sonar and drive, and the camera; loaded from TOML and ray cast.
//!
//! This is the first version the walking skeleton needs; locales, landmarks and meadows come
//! with the simulator issue.

mod load;
mod model;
mod raycast;

pub use load::{WorldError, load_str};
pub use model::*;
pub use raycast::Hit;

impl World {
    /// Loads a world file; errors name the file, line and field.
    pub fn load(path: &std::path::Path) -> Result<World, WorldError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| WorldError::Io { file: path.display().to_string(), detail: e.to_string() })?;
        load_str(&text, &path.display().to_string())
    }
}
