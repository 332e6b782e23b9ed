//! The goal table of door finding by sonar alone (`[mission.door]`, 001 §3.2): which wall, which
//! opening along it, how the wall is followed and the opening told, and how the robot goes
//! through; the ranges of its numbers and how they fit together.

use harvey_config::range::{OutOfRange, Range, check, check_int};
use harvey_config::spans::KeyPath;
use serde::Deserialize;

use super::bounds::LENGTH;
use super::bounds_goals::{GAIN, HALF_TURN, SPEED, TURN_GAIN, TURN_RATE};

/// How the robot finds and takes the doorway (001 §3.2 gives both).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DoorVariant {
    /// Follow the wall at an even distance, note where the side sonar's range jumps up and where
    /// it drops again, back up to halfway between, turn 90 degrees and drive through.
    WallFollow,
    /// Motor schemas (Chapter 8's system): the wall's echoes repel, move-ahead presses the robot
    /// along and into the wall; where the opening lets it, the press carries it into the doorway.
    Schemas,
}

/// Which side of the robot the wall is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Side {
    Left,
    Right,
}

impl Side {
    /// +1 for the left, -1 for the right (the sign of a turn towards the wall).
    pub fn sign(self) -> f64 {
        match self {
            Side::Left => 1.0,
            Side::Right => -1.0,
        }
    }
}

/// `[mission.door]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DoorGoal {
    pub variant: DoorVariant,
    pub side: Side,
    /// Take the `opening`-th door-sized opening along the wall (1: the first).
    pub opening: u32,
    /// An opening counts as a door when its width (as the side sensor's beam sees it) lies in
    /// this range (m); a narrower one is a notch, a wider one the wall's end.
    pub door_width_m: [f64; 2],
    /// The side range must rise this much above the wall (m), or bring no echo, to mean an
    /// opening, for `confirm` readings in a row (a single far reading is a lost echo or a stray),
    /// and come back within half of it, as many times, to mean the wall again.
    pub jump_m: f64,
    pub confirm: u32,
    /// The wall's readings over this much travel are fitted to a line (m); a reading further
    /// than `gate_m` from it is not the wall.
    pub fit_m: f64,
    pub gate_m: f64,
    /// The distance kept from the wall (robot's centre, m) and how hard the follower steers for
    /// it (degrees of heading per metre off, at most `max_approach_deg`).
    pub keep_m: f64,
    pub approach_deg_per_m: f64,
    pub max_approach_deg: f64,
    /// Driving: speed along the wall and backing (m/s), turn rate (degrees/s) and its gain (per
    /// second); a turn counts as done this near (degrees).
    pub speed_mps: f64,
    pub back_mps: f64,
    pub max_turn_degps: f64,
    pub turn_gain: f64,
    pub aligned_deg: f64,
    /// How far past the wall's line the robot goes into the room (m).
    pub through_m: f64,
    /// The schemas (variant `schemas`): move-ahead along the wall and into it (m/s), the wall's
    /// echoes repelling within `avoid_sphere_m` of the robot's edge at up to `avoid_gain`; the
    /// robot counts as drawn into the doorway once the schemas' sum turns this far towards the
    /// wall (degrees) over `drawn_for_m` of travel.
    #[serde(default)]
    pub along_mps: f64,
    #[serde(default)]
    pub press_mps: f64,
    #[serde(default)]
    pub avoid_sphere_m: f64,
    #[serde(default)]
    pub avoid_gain: f64,
    #[serde(default)]
    pub drawn_in_deg: f64,
    #[serde(default)]
    pub drawn_for_m: f64,
}

/// A turn towards or away from the wall, a sum's turn into it: up to square.
const QUARTER_TURN: Range = Range::closed(0.0, 90.0, "deg");

pub(crate) fn check_bounds(k: &KeyPath, d: &DoorGoal) -> Result<(), OutOfRange> {
    check_int(&k.key("opening"), d.opening, 1, 100, "openings")?;
    check(&k.key("door_width_m[0]"), d.door_width_m[0], &LENGTH)?;
    check(&k.key("door_width_m[1]"), d.door_width_m[1], &LENGTH)?;
    check(&k.key("jump_m"), d.jump_m, &LENGTH)?;
    // Readings in a row: each side reading comes every three of the DRV's banks.
    check_int(&k.key("confirm"), d.confirm, 1, 100, "readings")?;
    check(&k.key("fit_m"), d.fit_m, &LENGTH)?;
    check(&k.key("gate_m"), d.gate_m, &LENGTH)?;
    check(&k.key("keep_m"), d.keep_m, &LENGTH)?;
    check(&k.key("approach_deg_per_m"), d.approach_deg_per_m, &Range::closed(0.0, 3600.0, "deg/m"))?;
    check(&k.key("max_approach_deg"), d.max_approach_deg, &QUARTER_TURN)?;
    check(&k.key("speed_mps"), d.speed_mps, &SPEED)?;
    check(&k.key("back_mps"), d.back_mps, &SPEED)?;
    check(&k.key("max_turn_degps"), d.max_turn_degps, &TURN_RATE)?;
    check(&k.key("turn_gain"), d.turn_gain, &TURN_GAIN)?;
    check(&k.key("aligned_deg"), d.aligned_deg, &HALF_TURN)?;
    check(&k.key("through_m"), d.through_m, &LENGTH)?;
    check(&k.key("along_mps"), d.along_mps, &GAIN)?;
    check(&k.key("press_mps"), d.press_mps, &GAIN)?;
    check(&k.key("avoid_sphere_m"), d.avoid_sphere_m, &Range::closed(0.0, 20_000.0, "m"))?;
    check(&k.key("avoid_gain"), d.avoid_gain, &GAIN)?;
    check(&k.key("drawn_in_deg"), d.drawn_in_deg, &QUARTER_TURN)?;
    check(&k.key("drawn_for_m"), d.drawn_for_m, &Range::closed(0.0, 20_000.0, "m"))
}

pub(crate) fn check_door(d: &DoorGoal) -> Result<(), &'static str> {
    if d.door_width_m[0] >= d.door_width_m[1] {
        return Err("door_width_m's least is not below its most");
    }
    if d.gate_m >= d.jump_m / 2.0 {
        return Err("gate_m is not below half of jump_m (a reading on the wall must end an opening)");
    }
    if d.variant == DoorVariant::Schemas
        && (d.along_mps <= 0.0
            || d.press_mps <= 0.0
            || d.avoid_sphere_m <= 0.0
            || d.avoid_gain <= 0.0
            || d.drawn_in_deg <= 0.0)
    {
        return Err(
            "the schemas variant needs along_mps, press_mps, avoid_sphere_m, avoid_gain and drawn_in_deg",
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::mission::parse;

    #[test]
    fn the_door_table_is_read_and_its_parts_must_fit() {
        let text = include_str!("../../../../missions/door-finding.toml");
        let m = parse(text, "door-finding.toml").expect("parses");
        let d = m.door.expect("a door table");
        assert_eq!((d.variant, d.side.sign(), d.opening), (super::DoorVariant::WallFollow, 1.0, 1));
        let refused =
            |from: &str, to: &str| parse(&text.replace(from, to), "d.toml").expect_err("refused").to_string();
        assert!(refused("door_width_m = [0.5, 1.6]", "door_width_m = [1.6, 0.5]").contains("door_width_m"));
        assert!(refused("gate_m = 0.08", "gate_m = 0.4").contains("gate_m is not below half of jump_m"));
        assert!(
            refused("variant = \"wall-follow\"", "variant = \"schemas\"").contains("schemas variant needs")
        );
        assert!(refused("side = \"left\"", "side = \"up\"").contains("mission.door.side"));
        assert!(refused("confirm = 2", "confirm = 0").contains("mission.door.confirm"));
    }
}
