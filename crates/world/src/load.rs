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
    check_topology(w)
}

fn unique<'a>(what: &str, names: impl Iterator<Item = &'a str>) -> Result<(), String> {
    let mut seen = std::collections::BTreeSet::new();
    for n in names {
        if !seen.insert(n) {
            return Err(format!("two {what}s are named `{n}`"));
        }
    }
    Ok(())
}

fn check_topology(w: &World) -> Result<(), String> {
    unique("locale", w.locales.iter().map(|l| l.name.as_str()))?;
    unique("meadow", w.meadows.iter().map(|m| m.name.as_str()))?;
    unique("landmark", w.landmarks.iter().map(|l| l.name.as_str()))?;
    let locale = |n: &str| w.locales.iter().find(|l| l.name == n);
    for l in &w.locales {
        let mut seen = vec![l.name.as_str()];
        let mut parent = l.part_of.as_deref();
        while let Some(p) = parent {
            let up = locale(p).ok_or(format!("locale `{}` is part of missing locale `{p}`", l.name))?;
            if seen.contains(&p) {
                return Err(format!("locale `{}` is part of itself through {seen:?}", l.name));
            }
            seen.push(p);
            parent = up.part_of.as_deref();
        }
        if !l.outline.is_empty() && l.outline.len() < 3 {
            return Err(format!("locale `{}` has an outline of fewer than 3 points", l.name));
        }
    }
    for (i, d) in w.doors.iter().enumerate() {
        for n in &d.between {
            if locale(n).is_none() {
                return Err(format!("door[{i}] leads to missing locale `{n}`"));
            }
        }
        if !greater(d.width_m, 0.0) {
            return Err(format!("door[{i}] has no width"));
        }
    }
    for m in &w.meadows {
        if !w.terrain.contains_key(&m.terrain) {
            return Err(format!(
                "meadow `{}` has terrain `{}`, which is not in the terrain table",
                m.name, m.terrain
            ));
        }
        if m.outline.len() < 3 {
            return Err(format!("meadow `{}` has an outline of fewer than 3 points", m.name));
        }
        if let Some(l) = m.landmarks.iter().find(|l| w.landmark(l).is_none()) {
            return Err(format!("meadow `{}` lists missing landmark `{l}`", m.name));
        }
    }
    for l in &w.landmarks {
        if !w.meadows.iter().any(|m| m.landmarks.contains(&l.name)) {
            return Err(format!("landmark `{}` lies outside every meadow (no meadow lists it)", l.name));
        }
        if !greater(l.activation_range_m, 0.0) {
            return Err(format!("landmark `{}` has no activation range", l.name));
        }
        match l.class {
            crate::LandmarkClass::I if !greater(l.height_m, 0.0) => {
                return Err(format!("class I landmark `{}` needs a height_m", l.name));
            }
            crate::LandmarkClass::III if l.to_m.is_none() => {
                return Err(format!("class III landmark `{}` needs a to_m end", l.name));
            }
            _ => {}
        }
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
