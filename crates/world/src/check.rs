//! The checks that the numbers of a loaded world (and a launch file's movers) make a world, and
//! the typed reason when they do not.

use crate::World;

/// Why a parsed world (or a mover) is not a world: [`crate::WorldError::Inconsistent`]'s reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Inconsistency {
    #[error("ground `{ground}` is not in the terrain table")]
    UnknownGround { ground: String },
    #[error("a world needs at least one wall")]
    NoWalls,
    #[error("wall[{wall}] has no length or height")]
    EmptyWall { wall: usize },
    #[error("wall[{wall}].region[{region}] has its bounds reversed")]
    ReversedRegion { wall: usize, region: usize },
    #[error("camera needs a positive size, focal length and height")]
    Camera,
    #[error("robot speeds and sonar range must be positive")]
    Robot,
    #[error("floor tiles must have a positive size")]
    FloorTile,
    /// Two locales, meadows or landmarks (`what`) share a name.
    #[error("two {what}s are named `{name}`")]
    Duplicate { what: &'static str, name: String },
    #[error("locale `{locale}` is part of missing locale `{parent}`")]
    MissingParent { locale: String, parent: String },
    /// The part-of chain from `locale` comes back to a locale it passed (`through`, in order).
    #[error("locale `{locale}` is part of itself through {through:?}")]
    PartOfItself { locale: String, through: Vec<String> },
    #[error("locale `{locale}` has an outline of fewer than 3 points")]
    LocaleOutline { locale: String },
    #[error("door[{door}] leads to missing locale `{locale}`")]
    DoorToMissing { door: usize, locale: String },
    #[error("door[{door}] has no width")]
    DoorWidth { door: usize },
    #[error("meadow `{meadow}` has terrain `{terrain}`, which is not in the terrain table")]
    MeadowTerrain { meadow: String, terrain: String },
    #[error("meadow `{meadow}` has an outline of fewer than 3 points")]
    MeadowOutline { meadow: String },
    #[error("meadow `{meadow}` lists missing landmark `{landmark}`")]
    MeadowLandmark { meadow: String, landmark: String },
    #[error("landmark `{landmark}` lies outside every meadow (no meadow lists it)")]
    LandmarkOutside { landmark: String },
    #[error("landmark `{landmark}` has no activation range")]
    ActivationRange { landmark: String },
    #[error("class I landmark `{landmark}` needs a height_m")]
    ClassIHeight { landmark: String },
    #[error("class III landmark `{landmark}` needs a to_m end")]
    ClassIIIEnd { landmark: String },
    #[error("mover {mover}: needs 3 or more outline corners and a path of finite numbers")]
    MoverShape { mover: String },
    #[error("mover {mover}: path times must increase")]
    MoverTimes { mover: String },
    #[error(
        "mover {mover}: height must be positive, reflectances in 0..=1, bands `[from_m, to_m, reflectance]` rising within its height"
    )]
    MoverLook { mover: String },
}

use Inconsistency as E;

/// The world's numbers make a world: the first reason they do not, in the order checked.
pub(crate) fn check(w: &World) -> Result<(), Inconsistency> {
    if !w.terrain.contains_key(&w.ground) {
        return Err(E::UnknownGround { ground: w.ground.clone() });
    }
    if w.walls.is_empty() {
        return Err(E::NoWalls);
    }
    for (i, wall) in w.walls.iter().enumerate() {
        if !greater(wall.length_m(), 1e-6) || !greater(wall.height_m, 0.0) {
            return Err(E::EmptyWall { wall: i });
        }
        for (j, r) in wall.regions.iter().enumerate() {
            if r.along_m[0] > r.along_m[1] || r.height_m[0] > r.height_m[1] {
                return Err(E::ReversedRegion { wall: i, region: j });
            }
        }
    }
    let c = &w.camera;
    if c.width_px == 0 || c.height_px == 0 || !greater(c.focal_px, 0.0) || !greater(c.height_m, 0.0) {
        return Err(E::Camera);
    }
    let r = &w.robot;
    if !greater(r.speed_mps, 0.0) || !greater(r.turn_rate_degps, 0.0) || !greater(r.sonar_max_range_ft, 0.0) {
        return Err(E::Robot);
    }
    if !greater(w.floor.tile_m, 0.0) {
        return Err(E::FloorTile);
    }
    check_topology(w)
}

fn unique<'a>(what: &'static str, names: impl Iterator<Item = &'a str>) -> Result<(), Inconsistency> {
    let mut seen = std::collections::BTreeSet::new();
    for n in names {
        if !seen.insert(n) {
            return Err(E::Duplicate { what, name: n.to_owned() });
        }
    }
    Ok(())
}

fn check_topology(w: &World) -> Result<(), Inconsistency> {
    unique("locale", w.locales.iter().map(|l| l.name.as_str()))?;
    unique("meadow", w.meadows.iter().map(|m| m.name.as_str()))?;
    unique("landmark", w.landmarks.iter().map(|l| l.name.as_str()))?;
    let locale = |n: &str| w.locales.iter().find(|l| l.name == n);
    for l in &w.locales {
        let mut seen = vec![l.name.as_str()];
        let mut parent = l.part_of.as_deref();
        while let Some(p) = parent {
            let up =
                locale(p).ok_or_else(|| E::MissingParent { locale: l.name.clone(), parent: p.to_owned() })?;
            if seen.contains(&p) {
                let through = seen.iter().map(|s| (*s).to_owned()).collect();
                return Err(E::PartOfItself { locale: l.name.clone(), through });
            }
            seen.push(p);
            parent = up.part_of.as_deref();
        }
        if !l.outline.is_empty() && l.outline.len() < 3 {
            return Err(E::LocaleOutline { locale: l.name.clone() });
        }
    }
    for (i, d) in w.doors.iter().enumerate() {
        for n in &d.between {
            if locale(n).is_none() {
                return Err(E::DoorToMissing { door: i, locale: n.clone() });
            }
        }
        if !greater(d.width_m, 0.0) {
            return Err(E::DoorWidth { door: i });
        }
    }
    for m in &w.meadows {
        if !w.terrain.contains_key(&m.terrain) {
            return Err(E::MeadowTerrain { meadow: m.name.clone(), terrain: m.terrain.clone() });
        }
        if m.outline.len() < 3 {
            return Err(E::MeadowOutline { meadow: m.name.clone() });
        }
        if let Some(l) = m.landmarks.iter().find(|l| w.landmark(l).is_none()) {
            return Err(E::MeadowLandmark { meadow: m.name.clone(), landmark: l.clone() });
        }
    }
    for l in &w.landmarks {
        if !w.meadows.iter().any(|m| m.landmarks.contains(&l.name)) {
            return Err(E::LandmarkOutside { landmark: l.name.clone() });
        }
        if !greater(l.activation_range_m, 0.0) {
            return Err(E::ActivationRange { landmark: l.name.clone() });
        }
        match l.class {
            crate::LandmarkClass::I if !greater(l.height_m, 0.0) => {
                return Err(E::ClassIHeight { landmark: l.name.clone() });
            }
            crate::LandmarkClass::III if l.to_m.is_none() => {
                return Err(E::ClassIIIEnd { landmark: l.name.clone() });
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
    use super::Inconsistency;

    #[test]
    fn a_part_of_cycle_names_the_locales_it_went_through() {
        let e = Inconsistency::PartOfItself { locale: "a".into(), through: vec!["a".into(), "b".into()] };
        assert_eq!(e.to_string(), "locale `a` is part of itself through [\"a\", \"b\"]");
        let d = Inconsistency::Duplicate { what: "meadow", name: "lawn".into() };
        assert_eq!(d.to_string(), "two meadows are named `lawn`");
    }
}
