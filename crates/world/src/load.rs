//! Loading a world file: TOML parsing with errors that name file, line and field, then the
//! ranges of its numbers (`bounds.rs`) and the checks (`check.rs`) that they make a world.

use crate::World;
use crate::bounds::check_bounds;
use crate::check::{Inconsistency, check};
use harvey_config::range::OutOfRange;
use harvey_config::spans::{line_of, line_of_key};

/// Why a world could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    #[error("{file}: {detail}")]
    Io { file: String, detail: String },
    #[error("{file}:{line}: field `{field}`: {detail}")]
    Parse { file: String, line: usize, field: String, detail: String },
    /// A number outside its range, or a list longer than its cap (`bounds.rs`): the key, and
    /// the line where the file gives it (0 when the file leaves it to its default).
    #[error("{file}:{line}: field `{field}`: {detail}")]
    OutOfRange { file: String, line: usize, field: String, detail: String },
    /// Parsed, but the numbers make no world (or no mover): [`Inconsistency`] says why.
    #[error("{file}: inconsistent world: {why}")]
    Inconsistent { file: String, why: Inconsistency },
}

impl WorldError {
    /// `why` as the error of `file`, with the line of its key in `text`.
    pub(crate) fn out_of_range(text: &str, file: &str, why: OutOfRange) -> WorldError {
        let line = line_of_key(text, &why.key);
        WorldError::OutOfRange { file: file.to_owned(), line, field: why.key.to_string(), detail: why.detail }
    }
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
    check_bounds(&world).map_err(|why| WorldError::out_of_range(text, file, why))?;
    check(&world).map_err(|why| WorldError::Inconsistent { file: file.to_owned(), why })?;
    Ok(world)
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
        // Each stretch of the path and the lawns carries its own terrain and look.
        let at = |x, y| w.meadow_at(x, y).map(|m| m.terrain.as_str());
        assert_eq!(
            [at(2.0, 0.0), at(12.0, 0.0), at(24.0, 0.0), at(10.0, -5.0)],
            [Some("tile"), Some("concrete"), Some("gravel"), Some("dry_grass")]
        );
        assert_eq!(w.floor_reflectance_at(24.0, 0.0), [0.40, 0.33]);
        assert_eq!(w.locale_at(10.0, 3.0).map(|l| l.name.as_str()), Some("north-lawn"));
        let kinds: Vec<_> = ["lamppost-2", "entrance", "path-south-edge"]
            .iter()
            .map(|n| w.landmark(n).map(|l| l.class))
            .collect();
        assert_eq!(
            kinds,
            [Some(crate::LandmarkClass::I), Some(crate::LandmarkClass::II), Some(crate::LandmarkClass::III)]
        );
    }

    #[test]
    fn the_room_has_a_stereo_rig_obstacles_of_several_heights_and_a_goal_mat() {
        let w = load_str(include_str!("../../../worlds/room.toml"), "room.toml").expect("room loads");
        assert_eq!(w.camera.stereo_baseline_m, Some(0.25), "003's 25 cm");
        let mut heights: Vec<f64> = w.walls.iter().map(|x| x.height_m).filter(|h| *h < 2.6).collect();
        heights.dedup();
        assert_eq!(heights, [0.8, 0.9, 0.75, 1.8], "box, chair, table, cabinet");
        // The box stands on the straight line from the start to the goal, 2.2 m ahead.
        let hit = w.cast_ray([w.start.x_m, w.start.y_m], [1.0, 0.0], 10.0).expect("the box");
        assert!((hit.distance_m - 2.2).abs() < 1e-9 && (w.walls[hit.wall].height_m - 0.8).abs() < 1e-9);
        assert_eq!(w.floor_reflectance_at(7.2, 3.0), [0.92, 0.92]);
        assert_eq!(w.floor_reflectance_at(5.0, 3.0), w.floor.reflectance);
        // Without a rig the camera is a single one; a rig 3 m wide is refused.
        assert_eq!(load_str(HALLWAY, "hallway.toml").expect("loads").camera.stereo_baseline_m, None);
        let wide = include_str!("../../../worlds/room.toml")
            .replace("stereo_baseline_m = 0.25", "stereo_baseline_m = 3.0");
        let err = load_str(&wide, "room.toml").expect_err("too wide").to_string();
        assert!(err.contains("camera.stereo_baseline_m"), "{err}");
    }

    #[test]
    fn the_hallway_has_locales_doors_meadows_and_landmarks() {
        let w = load_str(HALLWAY, "hallway.toml").expect("hallway loads");
        assert_eq!(w.locale_at(3.0, 0.0).map(|l| l.name.as_str()), Some("hallway"));
        assert_eq!(w.locale_at(5.0, 3.0).map(|l| l.name.as_str()), Some("robot-lab"));
        assert_eq!(w.locale_at(12.0, 2.0).map(|l| l.name.as_str()), Some("teds-office"));
        assert_eq!(
            w.locales.iter().find(|l| l.name == "robot-lab").and_then(|l| l.part_of.as_deref()),
            Some("grc")
        );
        assert_eq!(w.doors.len(), 2);
        // The lab's floor is concrete, the hall's tile (Table 3's numbers differ).
        assert!((w.terrain_at(5.0, 3.0).translational_loss_ft_per_ft - 0.044).abs() < 1e-12);
        assert!((w.terrain_at(5.0, 0.0).translational_loss_ft_per_ft - 0.042).abs() < 1e-12);
        let sign = w.landmark("office-sign").expect("sign");
        assert_eq!(sign.class, crate::LandmarkClass::II);
        assert!(sign.active_from(6.0, 0.0, 0.0) && !sign.active_from(6.0, 0.0, 180.0));
        // The 40+ ft hall of 000 §5.5.
        assert!(w.walls.iter().any(|wall| wall.length_m() / 0.3048 > 40.0));
    }

    #[test]
    fn inconsistent_worlds_are_rejected_with_the_reason() {
        let cases =
            [
                (
                    HALLWAY.replacen(
                        "between = [\"hallway\", \"robot-lab\"]",
                        "between = [\"hallway\", \"attic\"]",
                        1,
                    ),
                    "door[0] leads to missing locale `attic`",
                ),
                (
                    HALLWAY
                        .replacen("landmarks = [\"office-door-west-jamb\"]", "landmarks = []", 1)
                        .replacen(", \"office-door-west-jamb\"", "", 1),
                    "landmark `office-door-west-jamb` lies outside every meadow",
                ),
                (
                    HALLWAY.replacen("part_of = \"grc\"", "part_of = \"campus\"", 1),
                    "locale `hallway` is part of missing locale `campus`",
                ),
                (
                    HALLWAY.replacen("terrain = \"concrete\"", "terrain = \"ice\"", 1),
                    "meadow `robot-lab-floor` has terrain `ice`",
                ),
                (
                    HALLWAY.replacen("to_m = [16.0, 1.0, 0.0]\n", "", 1),
                    "class III landmark `north-baseboard` needs a to_m end",
                ),
            ];
        for (text, reason) in cases {
            let err = load_str(&text, "w.toml").expect_err(reason).to_string();
            assert!(err.starts_with("w.toml: inconsistent world: ") && err.contains(reason), "{err}");
        }
    }

    #[test]
    fn an_unknown_ground_is_inconsistent() {
        let text = HALLWAY.replacen("ground = \"tile\"", "ground = \"ice\"", 1);
        let err = load_str(&text, "w.toml").expect_err("must fail").to_string();
        assert!(err.contains("ground `ice` is not in the terrain table"), "{err}");
    }
}
