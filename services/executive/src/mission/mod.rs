//! The mission a launch file gives the executive: a script of TURN and MOVE primitives with a
//! time limit, a move perhaps driven in increments and servoed on a landmark (000 §5.5); or a
//! goal `(ptrans a b)` that plan-and-monitor develops over the world's locale graph (000 §2).
//! Every number is checked against its range first (`bounds.rs`, refusals naming file, line and
//! key), then how the table's parts fit together (here and `goals.rs`).

use serde::Deserialize;

mod bounds;
mod bounds_goals;
pub mod depth;
pub mod door;
mod error;
pub mod goals;
pub mod path;

pub use depth::DepthGoal;
pub use door::{DoorGoal, DoorVariant, Side};
pub use error::MissionError;
pub use goals::{DockingGoal, NeptuneGoal, PolesGoal, PtransGoal};
use goals::{check_docking, check_neptune, check_poles, check_ptrans};
pub use path::PathGoal;

/// One primitive: exactly one of `move_m` and `turn_deg` is set. A move may be driven in
/// increments, and servoed on a landmark after each (000 §5.5).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    pub move_m: Option<f64>,
    pub turn_deg: Option<f64>,
    /// Drive the move in increments of this length.
    pub increment_m: Option<f64>,
    /// After each increment, servo on this landmark of the world (needs `increment_m`)…
    pub servo_landmark: Option<String>,
    /// …at this offset from the landmark's point (a vertex where reflectances meet, 000 §5.2).
    #[serde(default)]
    pub servo_vertex_m: [f64; 3],
    /// Plan-level servoing (000 §5.6): find the `[mission.refine]` vertices and refine the
    /// robot's pose from them, instead of moving.
    #[serde(default)]
    pub refine_pose: bool,
    /// Before refining, believe the robot this far (m, world x and y) from where odometry says:
    /// an expected pose off target, as in 000 Table 1.
    pub belief_offset_m: Option<[f64; 2]>,
}

/// Plan-level servoing settings (`[mission.refine]`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Refine {
    /// Landmark vertices (world, m) to find by correlation (000 §5.2: where reflectances meet).
    #[serde(default)]
    pub vertices_m: Vec<[f64; 3]>,
    /// Or chosen from the world model (000 §5.2): every corner of a painted region whose
    /// reflectance differs from its wall's by at least this much (those in view of each pose
    /// are asked for).
    pub select_contrast: Option<f64>,
    /// With more vertices in view than a fix can ask for (16), which: `nearest` or
    /// `most-telling`, those that most shrink the fix's expected position spread (000 §5.1:
    /// landmarks chosen for the information they offer).
    #[serde(default)]
    pub choose: crate::servo::vertices::Choose,
    pub template_px: u32,
    pub min_score: f64,
    /// How well the expected pose is known: x, y (m) and heading (degrees).
    pub prior_sd: [f64; 3],
    /// A vertex further than this (pixels) from where the refined pose puts it is dropped.
    pub gate_px: f64,
    /// A fix that places the robot no better than this (m, `Refined::position_sd_m`) is not
    /// taken: its vertices leave sideways and turned too hard to tell apart.
    #[serde(default)]
    pub max_sd_m: Option<f64>,
}

/// Action-level servoing settings (`[mission.servo]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Servo {
    /// The point ahead on the intended line to steer for (m).
    pub aim_m: f64,
    /// The camera's yaw from the direction of motion, as calibrated (degrees, left positive).
    #[serde(default)]
    pub misalignment_deg: f64,
    /// Measure the mount's yaw and pitch at the start of each servoed leg, from the landmark
    /// seen where the robot stands on the line (the robot's calibration is never exact).
    #[serde(default)]
    pub calibrate_mount: bool,
    /// A sighting implying a heading error over `gate_deg` (default 3: 002 Table 3's drift is
    /// 0.27 deg/ft, half a degree an increment), or a distance off by more than the fraction
    /// `gate_range` (default 0.1: the loss is 4 % per foot), is refused as a false match.
    #[serde(default = "default_gate_deg")]
    pub gate_deg: f64,
    #[serde(default = "default_gate_range")]
    pub gate_range: f64,
    /// Side of the appearance template (pixels) and least correlation score of a sighting.
    pub template_px: u32,
    pub min_score: f64,
    /// `increment` (000 §5.5 as written) or `whole` (the default: the offset summed over the
    /// leg's increments).
    #[serde(default)]
    pub offset: crate::script::leg::Tracking,
}

fn default_gate_deg() -> f64 {
    3.0
}

fn default_gate_range() -> f64 {
    0.1
}

/// The `[mission]` table of a launch file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mission {
    pub description: String,
    /// Simulated seconds before the mission counts as failed.
    pub timeout_s: f64,
    #[serde(default, rename = "step")]
    pub steps: Vec<Step>,
    pub servo: Option<Servo>,
    pub refine: Option<Refine>,
    pub ptrans: Option<PtransGoal>,
    pub docking: Option<DockingGoal>,
    pub poles: Option<PolesGoal>,
    pub neptune: Option<NeptuneGoal>,
    pub door: Option<DoorGoal>,
    pub path: Option<PathGoal>,
    pub depth: Option<DepthGoal>,
}

#[derive(Deserialize)]
struct File {
    mission: Option<Mission>,
}

/// Reads the `[mission]` table of a launch file; other tables belong to the supervisor.
pub fn parse(text: &str, file: &str) -> Result<Mission, MissionError> {
    let file_name = || file.to_owned();
    let doc: toml::Table = toml::from_str(text)
        .map_err(|e| MissionError::Toml { file: file_name(), message: e.message().to_owned() })?;
    let only_mission: toml::Table = doc.into_iter().filter(|(k, _)| k == "mission").collect();
    let parsed: File = serde_path_to_error::deserialize(only_mission).map_err(|e| MissionError::Field {
        file: file_name(),
        path: e.path().to_string(),
        message: e.inner().message().to_owned(),
    })?;
    let m = parsed.mission.ok_or_else(|| MissionError::NoMission { file: file_name() })?;
    bounds::check_bounds(&m).map_err(|why| MissionError::OutOfRange {
        file: file_name(),
        line: harvey_config::line_of_key(text, &why.key),
        key: why.key.to_string(),
        detail: why.detail,
    })?;
    if !greater(m.timeout_s, 0.0) {
        return Err(MissionError::Timeout { file: file_name() });
    }
    let behaviours = usize::from(m.ptrans.is_some())
        + usize::from(m.docking.is_some())
        + usize::from(m.poles.is_some())
        + usize::from(m.neptune.is_some())
        + usize::from(m.door.is_some())
        + usize::from(m.path.is_some())
        + usize::from(m.depth.is_some());
    match (behaviours, m.steps.is_empty()) {
        (0, true) => return Err(MissionError::NothingToDo { file: file_name() }),
        (1, true) | (0, false) => {}
        _ => return Err(MissionError::TooMuchToDo { file: file_name() }),
    }
    let goal = |table, what| MissionError::Goal { file: file_name(), table, what };
    if let Some(p) = &m.poles {
        check_poles(p).map_err(|what| goal("poles", what))?;
    }
    if let Some(p) = &m.ptrans {
        check_ptrans(p).map_err(|what| goal("ptrans", what))?;
    }
    if let Some(d) = &m.docking {
        check_docking(d).map_err(|what| goal("docking", what))?;
    }
    if let Some(n) = &m.neptune {
        check_neptune(n).map_err(|what| goal("neptune", what))?;
    }
    if let Some(d) = &m.door {
        door::check_door(d).map_err(|what| goal("door", what))?;
    }
    if let Some(p) = &m.path {
        path::check_path(p).map_err(|what| goal("path", what))?;
    }
    if let Some(d) = &m.depth {
        depth::check_depth(d).map_err(|what| goal("depth", what))?;
    }
    for (index, s) in m.steps.iter().enumerate() {
        match (s.move_m, s.turn_deg, s.refine_pose) {
            (Some(v), None, false) | (None, Some(v), false) if v.is_finite() => {}
            (None, None, true)
                if m.refine
                    .as_ref()
                    .is_some_and(|r| r.vertices_m.len() >= 2 || r.select_contrast.is_some()) => {}
            _ => return Err(MissionError::Step { file: file_name(), index }),
        }
        if let Some(inc) = s.increment_m
            && (s.move_m.is_none() || !greater(inc, 0.0))
        {
            return Err(MissionError::Increment { file: file_name(), index });
        }
        if s.servo_landmark.is_some() && (s.increment_m.is_none() || m.servo.is_none()) {
            return Err(MissionError::ServoLandmark { file: file_name(), index });
        }
    }
    if let Some(sv) = m.servo
        && (!greater(sv.aim_m, 0.0) || !sv.misalignment_deg.is_finite() || sv.template_px < 4)
    {
        return Err(MissionError::Servo { file: file_name() });
    }
    Ok(m)
}

/// `v > min`, false for NaN: the check that a number is usable.
pub(crate) fn greater(v: f64, min: f64) -> bool {
    v > min
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mission_table_is_read_and_checked() {
        let text = "[launch]\nname = \"x\"\n[mission]\ndescription = \"d\"\ntimeout_s = 60\n[[mission.step]]\nmove_m = 2.0\n[[mission.step]]\nturn_deg = 90\n";
        let m = parse(text, "m.toml").expect("parses");
        assert_eq!(
            m.steps,
            vec![
                Step { move_m: Some(2.0), ..Step::default() },
                Step { turn_deg: Some(90.0), ..Step::default() }
            ]
        );
        let both = text.replace("turn_deg = 90", "turn_deg = 90\nmove_m = 1");
        assert!(parse(&both, "m.toml").expect_err("two fields").to_string().contains("mission.step[1]"));
        let typo = text.replace("timeout_s", "timeout");
        assert!(
            parse(&typo, "m.toml").expect_err("unknown field").to_string().contains("m.toml: field `mission")
        );
        let servoed =
            text.replace("move_m = 2.0", "move_m = 2.0\nincrement_m = 0.5\nservo_landmark = \"sign\"");
        let e = parse(&servoed, "m.toml").expect_err("no servo table").to_string();
        assert!(e.contains("step[0].servo_landmark needs"), "{e}");
        let table = format!("{servoed}[mission.servo]\naim_m = 1.2\ntemplate_px = 16\nmin_score = 0.9\n");
        let m = parse(&table, "m.toml").expect("parses");
        assert_eq!((m.steps[0].increment_m, m.servo.map(|s| s.aim_m)), (Some(0.5), Some(1.2)));
        let ptrans = "[mission]\ndescription = \"d\"\ntimeout_s = 60\n[mission.ptrans]\nto = \"office\"\ngoal_m = [1.0, 2.0]\ngoal_heading_deg = 90\napproach_m = 0.4\ndoor_depth_m = 0.6\nmilestone_m = 0.15\ngoal_tolerance_m = 0.01\nescalate_m = 0.5\nattempts = 3\nback_off_m = 0.3\n";
        assert_eq!(parse(ptrans, "p.toml").expect("parses").ptrans.map(|p| p.goal_m), Some([1.0, 2.0]));
        let both = format!("{ptrans}[[mission.step]]\nmove_m = 1.0\n");
        assert!(parse(&both, "p.toml").expect_err("steps too").to_string().contains("no [[mission.step]]"));
        let tight = ptrans.replace("escalate_m = 0.5", "escalate_m = 0.1");
        assert!(
            parse(&tight, "p.toml").expect_err("escalate").to_string().contains("mission.ptrans: escalate_m")
        );
        let on_turn = text.replace("turn_deg = 90", "turn_deg = 90\nincrement_m = 0.5");
        assert!(parse(&on_turn, "m.toml").expect_err("turn").to_string().contains("step[1].increment_m"));
    }
}
