//! Loading a world file: TOML parsing with errors that name file, line and field, then checks
//! that the numbers make a world.

use crate::World;

/// Why a world could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    #[error("{file}: {detail}")]
    Io { file: String, detail: String },
    #[error("{file}:{line}: field `{field}`: {detail}")]
    Parse { file: String, line: usize, field: String, detail: String },
    #[error("{file}: inconsistent world: {detail}")]
    Inconsistent { file: String, detail: String },
}

fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

/// Parses a world from `text`; `file` names it in errors.
pub fn load_str(text: &str, file: &str) -> Result<World, WorldError> {
    let de = toml::Deserializer::new(text);
    let world: World = serde_path_to_error::deserialize(de).map_err(|e| {
        let field = e.path().to_string();
        let inner = e.into_inner();
        let line = inner.span().map_or(0, |s| line_of(text, s.start));
        WorldError::Parse { file: file.to_owned(), line, field, detail: inner.message().to_owned() }
    })?;
    check(&world).map_err(|detail| WorldError::Inconsistent { file: file.to_owned(), detail })?;
    Ok(world)
}

fn check(w: &World) -> Result<(), String> {
    if !w.terrain.contains_key(&w.ground) {
        return Err(format!("ground `{}` is not in the terrain table", w.ground));
    }
    if w.walls.is_empty() {
        return Err("a world needs at least one wall".into());
    }
    for (i, wall) in w.walls.iter().enumerate() {
        if !greater(wall.length_m(), 1e-6) || !greater(wall.height_m, 0.0) {
            return Err(format!("wall[{i}] has no length or height"));
        }
        for (j, r) in wall.regions.iter().enumerate() {
            if r.along_m[0] > r.along_m[1] || r.height_m[0] > r.height_m[1] {
                return Err(format!("wall[{i}].region[{j}] has its bounds reversed"));
            }
        }
    }
    let c = &w.camera;
    if c.width_px == 0 || c.height_px == 0 || !greater(c.focal_px, 0.0) || !greater(c.height_m, 0.0) {
        return Err("camera needs a positive size, focal length and height".into());
    }
    let r = &w.robot;
    if !greater(r.speed_mps, 0.0) || !greater(r.turn_rate_degps, 0.0) || !greater(r.sonar_max_range_ft, 0.0) {
        return Err("robot speeds and sonar range must be positive".into());
    }
    if !greater(w.floor.tile_m, 0.0) {
        return Err("floor tiles must have a positive size".into());
    }
    Ok(())
}

/// `v > min`, false for NaN: the check that a number is usable.
fn greater(v: f64, min: f64) -> bool {
    v > min
}

#[cfg(test)]
mod tests {
    use super::*;

    const HALLWAY: &str = include_str!("../../../worlds/hallway.toml");

    #[test]
    fn the_hallway_loads() {
        let w = load_str(HALLWAY, "hallway.toml").expect("hallway loads");
        assert_eq!(w.name, "hallway");
        assert!((w.ground_terrain().translational_loss_ft_per_ft - 0.042).abs() < 1e-12);
        assert!(w.walls.len() >= 4);
    }

    #[test]
    fn a_bad_value_names_line_and_field() {
        let text = HALLWAY.replacen("height_m = 1.2", "height_m = \"tall\"", 1);
        let line = text.lines().position(|l| l.contains("\"tall\"")).expect("edited") + 1;
        let err = load_str(&text, "w.toml").expect_err("must fail").to_string();
        assert!(err.starts_with(&format!("w.toml:{line}: field `camera.height_m`")), "{err}");
    }

    #[test]
    fn the_campus_has_all_four_terrains_of_table_3() {
        let w = load_str(include_str!("../../../worlds/campus.toml"), "campus.toml").expect("campus loads");
        let names: Vec<&str> = w.terrain.keys().map(String::as_str).collect();
        assert_eq!(names, ["concrete", "dry_grass", "gravel", "tile"]);
        assert!((w.terrain["dry_grass"].translational_sd_ft_per_ft - 0.0042).abs() < 1e-12);
    }

    #[test]
    fn an_unknown_ground_is_inconsistent() {
        let text = HALLWAY.replacen("ground = \"tile\"", "ground = \"ice\"", 1);
        let err = load_str(&text, "w.toml").expect_err("must fail").to_string();
        assert!(err.contains("ground `ice` is not in the terrain table"), "{err}");
    }
}
