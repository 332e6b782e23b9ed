//! The mission a launch file gives the executive: a script of TURN and MOVE primitives with a
//! time limit, a move perhaps driven in increments and servoed on a landmark (000 §5.5); or a
//! goal `(ptrans a b)` that plan-and-monitor develops over the world's locale graph (000 §2).

use serde::Deserialize;

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
    pub vertices_m: Vec<[f64; 3]>,
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
    /// Side of the appearance template (pixels) and least correlation score of a sighting.
    pub template_px: u32,
    pub min_score: f64,
    /// `increment` (000 §5.5 as written) or `whole` (the default: the offset summed over the
    /// leg's increments).
    #[serde(default)]
    pub offset: crate::leg::Tracking,
}

/// A goal for plan-and-monitor (`[mission.ptrans]`, 000 §2, §4): get to a place in locale `to`
/// from wherever the robot starts, checking a milestone after each subgoal.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PtransGoal {
    /// The goal locale (a locale of the world), and the place in it (m) with the heading to take.
    pub to: String,
    pub goal_m: [f64; 2],
    pub goal_heading_deg: f64,
    /// The last subgoal comes in along the goal heading from this far back, so the robot arrives
    /// facing the right way and never turns far on the spot at the goal (turns skitter, 002 §3.2).
    pub approach_m: f64,
    /// How far either side of a doorway its milestones are.
    pub door_depth_m: f64,
    /// A milestone is reached when the robot is believed this close to it; the goal, `goal_m`.
    pub milestone_m: f64,
    pub goal_tolerance_m: f64,
    /// A milestone missed by less than this is retried from where the robot is (plan level);
    /// by more, or `attempts` times, the plan is developed afresh from there (goal level).
    pub escalate_m: f64,
    pub attempts: u32,
    /// A target closer than this is moved to straight, if nearly dead ahead or behind, or else
    /// approached by backing off first.
    pub back_off_m: f64,
}

/// A docking behaviour sequenced by a finite state acceptor (`[mission.docking]`, 004 §4.2).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DockingGoal {
    /// The acceptor's file, relative to the launch file (`fsa/docking.toml`), and the accepting
    /// state that means docked (the other accepting states are failures).
    pub fsa: String,
    pub docked_state: String,
    /// The dock face's centre on the floor and the way the face looks (degrees).
    pub dock_m: [f64; 2],
    pub dock_facing_deg: f64,
    /// The Hough model: the frame's width (m; the model is 2 units wide) and its centre's height.
    pub frame_width_m: f64,
    pub frame_height_m: f64,
    /// The tracking target: a square of this side, its centre's height, its grey levels.
    pub target_side_m: f64,
    pub target_height_m: f64,
    pub target_grey: [f64; 2],
    /// The phototropic cue counts only a region this bright (grey level): with the lamp hidden,
    /// the brightest thing in view is something else.
    pub light_min_grey: f64,
    /// The Hough is tried once the dock is believed this near, give or take (scale hypotheses),
    /// with matches covering at least this share of the model; after a failure, once the robot
    /// has moved this far for a new view.
    pub hough_range_m: f64,
    pub hough_range_sd_m: f64,
    pub hough_min_certainty: f64,
    pub retry_after_m: f64,
    /// Tracking steers for the dock's axis this far ahead of the robot (the approach zone), and
    /// hands over to the sonar when the target covers this many pixels.
    pub lead_m: f64,
    /// Controlled motion keeps within this of the target's bearing (degrees), so that the
    /// target stays in the image.
    pub keep_in_view_deg: f64,
    pub close_area_px: f64,
    /// While tracking, every this many ticks a fix from the Hough's frame, while the robot is
    /// further than `fix_beyond_m` from the face (nearer, the frame leaves the image).
    pub fix_every_ticks: u32,
    pub fix_beyond_m: f64,
    /// After the first, a fix further than these from the belief is taken as a misreading.
    pub fix_gate_m: f64,
    pub fix_gate_deg: f64,
    /// Docked when the robot's centre is this far from the face; closer than `too_close_m` is
    /// a fatal error.
    pub final_m: f64,
    pub too_close_m: f64,
    /// Ballistic and controlled speeds (m/s), turn rate limit (degrees/s) and gain (per second).
    pub ballistic_mps: f64,
    pub controlled_mps: f64,
    pub max_turn_degps: f64,
    pub turn_gain: f64,
    /// avoid-static-obstacle's sphere of influence beyond the robot (m) and gain (m/s); the
    /// noise schema's size (m/s) and how many ticks each direction is held.
    pub avoid_sphere_m: f64,
    pub avoid_gain: f64,
    pub noise_mps: f64,
    pub noise_ticks: u32,
}

/// The pole hunt of the AAAI-92 competition (`[mission.poles]`, 004 §5): visit every coded
/// pole of the arena, each by the move-to-pole acceptor.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolesGoal {
    /// The acceptor's file, relative to the launch file, and its state that means parked.
    pub fsa: String,
    pub parked_state: String,
    /// Poles there are; the mission counts as done with `enough` of them visited at its end.
    pub count: u32,
    pub enough: u32,
    /// q0: each look turns the robot this far (half the field of view, 004 §5.3), a pole
    /// within `centred_deg` of the image centre is centred; after a whole turn with nothing
    /// new, wander for `wander_s` to look from elsewhere.
    pub sweep_deg: f64,
    pub centred_deg: f64,
    pub wander_s: f64,
    /// q2: ballistic motion ends this near the pole (believed), or when the timer runs out:
    /// `timer_slack_s` beyond the time the distance takes at the top speed.
    pub near_m: f64,
    pub timer_slack_s: f64,
    /// q1: how long the robot waits for the IR beacon to come round.
    pub beacon_wait_s: f64,
    /// After parking, back away for this long (at the controlled speed) before looking again.
    pub back_off_s: f64,
    /// q3: parked when the nearest echo towards the pole is this far from the robot's centre;
    /// no echo within `lost_m` in that direction and the pole is lost.
    pub park_m: f64,
    pub lost_m: f64,
    /// Speeds (m/s), turn rate (degrees/s) and its gain (per second).
    pub ballistic_mps: f64,
    pub controlled_mps: f64,
    pub max_turn_degps: f64,
    pub turn_gain: f64,
    /// The schemas of q2 (004 §5.3): avoid-static-obstacle's sphere (m) and gain, probe's and
    /// avoid-past's gains (m/s), avoid-past's cell (m) and per-tick decay, noise (m/s, ticks).
    pub avoid_sphere_m: f64,
    pub avoid_gain: f64,
    pub probe_gain: f64,
    pub past_gain: f64,
    pub past_cell_m: f64,
    pub past_decay: f64,
    pub noise_mps: f64,
    pub noise_ticks: u32,
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
}

#[derive(Deserialize)]
struct File {
    mission: Option<Mission>,
}

/// Reads the `[mission]` table of a launch file; other tables belong to the supervisor.
pub fn parse(text: &str, file: &str) -> Result<Mission, String> {
    let doc: toml::Table = toml::from_str(text).map_err(|e| format!("{file}: {}", e.message()))?;
    let only_mission: toml::Table = doc.into_iter().filter(|(k, _)| k == "mission").collect();
    let parsed: File = serde_path_to_error::deserialize(only_mission)
        .map_err(|e| format!("{file}: field `{}`: {}", e.path(), e.inner().message()))?;
    let m = parsed.mission.ok_or_else(|| format!("{file}: no [mission] table"))?;
    if !greater(m.timeout_s, 0.0) {
        return Err(format!("{file}: mission.timeout_s must be positive"));
    }
    let behaviours =
        usize::from(m.ptrans.is_some()) + usize::from(m.docking.is_some()) + usize::from(m.poles.is_some());
    match (behaviours, m.steps.is_empty()) {
        (0, true) => {
            return Err(format!(
                "{file}: the mission has no [[mission.step]], [mission.ptrans], [mission.docking] or [mission.poles]"
            ));
        }
        (1, true) | (0, false) => {}
        _ => {
            return Err(format!(
                "{file}: [mission.ptrans], [mission.docking] and [mission.poles] make their own steps: one of \
                 them, and no [[mission.step]]"
            ));
        }
    }
    if let Some(p) = &m.poles {
        check_poles(p).map_err(|e| format!("{file}: mission.poles: {e}"))?;
    }
    if let Some(p) = &m.ptrans {
        check_ptrans(p).map_err(|e| format!("{file}: mission.ptrans: {e}"))?;
    }
    if let Some(d) = &m.docking {
        check_docking(d).map_err(|e| format!("{file}: mission.docking: {e}"))?;
    }
    for (i, s) in m.steps.iter().enumerate() {
        match (s.move_m, s.turn_deg, s.refine_pose) {
            (Some(v), None, false) | (None, Some(v), false) if v.is_finite() => {}
            (None, None, true) if m.refine.as_ref().is_some_and(|r| r.vertices_m.len() >= 2) => {}
            _ => {
                return Err(format!(
                    "{file}: mission.step[{i}] needs exactly one finite `move_m` or `turn_deg`, or \
                     `refine_pose` with two or more [mission.refine] vertices_m"
                ));
            }
        }
        if let Some(inc) = s.increment_m
            && (s.move_m.is_none() || !greater(inc, 0.0))
        {
            return Err(format!("{file}: mission.step[{i}].increment_m must be positive, on a move"));
        }
        if s.servo_landmark.is_some() && (s.increment_m.is_none() || m.servo.is_none()) {
            return Err(format!(
                "{file}: mission.step[{i}].servo_landmark needs `increment_m` and a [mission.servo] table"
            ));
        }
    }
    if let Some(sv) = m.servo
        && (!greater(sv.aim_m, 0.0) || !sv.misalignment_deg.is_finite() || sv.template_px < 4)
    {
        return Err(format!("{file}: mission.servo: aim_m must be positive, template_px at least 4"));
    }
    Ok(m)
}

fn check_ptrans(p: &PtransGoal) -> Result<(), String> {
    let lengths =
        [p.approach_m, p.door_depth_m, p.milestone_m, p.goal_tolerance_m, p.escalate_m, p.back_off_m];
    if !lengths.iter().all(|&v| greater(v, 0.0)) || !p.goal_heading_deg.is_finite() {
        return Err("lengths must be positive and the heading finite".into());
    }
    if !p.goal_m.iter().all(|v| v.is_finite()) || p.attempts == 0 {
        return Err("goal_m must be finite and attempts at least 1".into());
    }
    if p.escalate_m <= p.milestone_m.max(p.goal_tolerance_m) {
        return Err("escalate_m must exceed milestone_m and goal_tolerance_m".into());
    }
    Ok(())
}

fn check_docking(d: &DockingGoal) -> Result<(), String> {
    let positive = [
        d.frame_width_m,
        d.target_side_m,
        d.hough_range_m,
        d.retry_after_m,
        d.lead_m,
        d.close_area_px,
        d.final_m,
        d.ballistic_mps,
        d.controlled_mps,
        d.max_turn_degps,
        d.turn_gain,
        d.avoid_sphere_m,
    ];
    if !positive.iter().all(|&v| greater(v, 0.0)) {
        return Err("sizes, ranges, speeds and gains must be positive".into());
    }
    let finite = [d.dock_m[0], d.dock_m[1], d.dock_facing_deg, d.frame_height_m, d.target_height_m];
    if !(finite.iter().all(|v| v.is_finite()) && d.hough_range_sd_m >= 0.0 && d.noise_mps >= 0.0) {
        return Err("the dock's place and the spreads must be finite".into());
    }
    if !(0.0..=1.0).contains(&d.hough_min_certainty) || !greater(d.final_m, d.too_close_m) {
        return Err("hough_min_certainty must be in 0..1 and too_close_m under final_m".into());
    }
    if !(0.0 <= d.target_grey[0] && d.target_grey[0] <= d.target_grey[1] && d.target_grey[1] <= 255.0) {
        return Err("target_grey must be two grey levels, low then high".into());
    }
    Ok(())
}

fn check_poles(p: &PolesGoal) -> Result<(), String> {
    let positive = [
        p.sweep_deg,
        p.centred_deg,
        p.wander_s,
        p.near_m,
        p.park_m,
        p.lost_m,
        p.ballistic_mps,
        p.controlled_mps,
        p.max_turn_degps,
        p.turn_gain,
        p.avoid_sphere_m,
        p.past_cell_m,
    ];
    if !positive.iter().all(|&v| greater(v, 0.0)) || !(0.0..=1.0).contains(&p.past_decay) {
        return Err("angles, times, distances, speeds and gains must be positive, past_decay in 0..1".into());
    }
    if p.count == 0 || p.enough > p.count || !greater(p.lost_m, p.park_m) || !greater(p.near_m, p.park_m) {
        return Err("count at least 1, enough at most count, lost_m and near_m beyond park_m".into());
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
        assert!(parse(&both, "m.toml").expect_err("two fields").contains("mission.step[1]"));
        let typo = text.replace("timeout_s", "timeout");
        assert!(parse(&typo, "m.toml").expect_err("unknown field").contains("m.toml: field `mission"));
        let servoed =
            text.replace("move_m = 2.0", "move_m = 2.0\nincrement_m = 0.5\nservo_landmark = \"sign\"");
        let e = parse(&servoed, "m.toml").expect_err("no servo table");
        assert!(e.contains("step[0].servo_landmark needs"), "{e}");
        let table = format!("{servoed}[mission.servo]\naim_m = 1.2\ntemplate_px = 16\nmin_score = 0.9\n");
        let m = parse(&table, "m.toml").expect("parses");
        assert_eq!((m.steps[0].increment_m, m.servo.map(|s| s.aim_m)), (Some(0.5), Some(1.2)));
        let ptrans = "[mission]\ndescription = \"d\"\ntimeout_s = 60\n[mission.ptrans]\nto = \"office\"\ngoal_m = [1.0, 2.0]\ngoal_heading_deg = 90\napproach_m = 0.4\ndoor_depth_m = 0.6\nmilestone_m = 0.15\ngoal_tolerance_m = 0.01\nescalate_m = 0.5\nattempts = 3\nback_off_m = 0.3\n";
        assert_eq!(parse(ptrans, "p.toml").expect("parses").ptrans.map(|p| p.goal_m), Some([1.0, 2.0]));
        let both = format!("{ptrans}[[mission.step]]\nmove_m = 1.0\n");
        assert!(parse(&both, "p.toml").expect_err("steps too").contains("no [[mission.step]]"));
        let tight = ptrans.replace("escalate_m = 0.5", "escalate_m = 0.1");
        assert!(parse(&tight, "p.toml").expect_err("escalate").contains("mission.ptrans: escalate_m"));
        let on_turn = text.replace("turn_deg = 90", "turn_deg = 90\nincrement_m = 0.5");
        assert!(parse(&on_turn, "m.toml").expect_err("turn").contains("step[1].increment_m"));
    }
}
