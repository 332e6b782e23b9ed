//! The goal tables of the missions that make their own steps: `[mission.ptrans]` for
//! plan-and-monitor (000 §2), `[mission.docking]` and `[mission.poles]` for the behaviours that
//! finite state acceptors sequence (004 §4.2, §5), `[mission.neptune]` for CMU's stop-go-stop
//! stereo navigation (003), each with its checks.

use serde::Deserialize;

use super::greater;

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
    /// The phototropic cue counts only a region this many times brighter than the window's
    /// median grey level (with the lamp hidden, the brightest thing in view is something
    /// else)...
    pub light_contrast: f64,
    /// ...and only a region the lamp's size could make: above the optical centre (the lamp is
    /// above the camera), no bigger than a lamp of `lamp_area_m2` seen from `light_near_m`.
    pub lamp_area_m2: f64,
    pub light_near_m: f64,
    /// The Hough is tried once the dock is believed this near, give or take (scale hypotheses),
    /// with matches covering at least this share of the model; after a failure, once the robot
    /// has moved this far for a new view.
    pub hough_range_m: f64,
    pub hough_range_sd_m: f64,
    pub hough_min_certainty: f64,
    /// The Hough's scale hypotheses span the distances from the dock's face that the UMS's region
    /// allows (004 §4.1.2), widened by this either way (m); `hough_range_sd_m` either way of
    /// the belief while the UMS has published no region.
    #[serde(default = "default_hough_band_min_m")]
    pub hough_band_min_m: f64,
    pub retry_after_m: f64,
    /// Tracking steers for the dock's axis this far ahead of the robot (the approach zone), and
    /// hands over to the sonar when the target covers this many pixels.
    pub lead_m: f64,
    /// Controlled motion keeps within this of the target's bearing (degrees), so that the
    /// target stays in the image.
    pub keep_in_view_deg: f64,
    /// The approach zone (004 §4.2): the cone of this half-angle round the dock's axis. A robot
    /// out of it in q0 (beside the dock, or past it) goes back to the axis,
    /// `hough_range_m - hough_range_sd_m / 2` out; the Hough is tried only inside it, with the dock
    /// believed in the camera's field of view.
    #[serde(default = "default_approach_cone_deg")]
    pub approach_cone_deg: f64,
    pub close_area_px: f64,
    /// While tracking, every this many ticks a fix from the Hough's frame, while the robot is
    /// further than `fix_beyond_m` from the face (nearer, the frame leaves the image).
    pub fix_every_ticks: u32,
    pub fix_beyond_m: f64,
    /// After the first, a fix further than these from the belief is taken as a misreading.
    pub fix_gate_m: f64,
    pub fix_gate_deg: f64,
    /// A fix's heading from the posts is weighed against the belief's: each post's height is
    /// read to this (pixels), and odometry's heading drifts this much a metre (degrees).
    pub post_height_sd_px: f64,
    pub heading_drift_deg_per_m: f64,
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
    /// Pole recognition: a pixel is ring tape from this many times the frame's bright
    /// background (the vision workers' adaptive threshold, `poles.rs`).
    pub ring_contrast: f64,
    /// q2: ballistic motion ends this near the pole (believed), or when the timer runs out:
    /// `timer_slack_s` beyond the time the distance takes at the top speed.
    pub near_m: f64,
    pub timer_slack_s: f64,
    /// q1: how long the robot waits for the IR beacon to come round.
    pub beacon_wait_s: f64,
    /// After parking, back away for this long (at the controlled speed) before looking again.
    pub back_off_s: f64,
    /// q3: parked when the nearest echo towards the pole is this far from the robot's centre;
    /// no echo within `lost_m` in that direction for `lost_after_s` and the pole is lost.
    pub park_m: f64,
    pub lost_m: f64,
    pub lost_after_s: f64,
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

/// CMU's stop-go-stop navigation by stereo alone (`[mission.neptune]`, 003): to the goal in
/// steps, looking at each stop, the position model from visual odometry, the path planned round
/// the obstacles stereo saw.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NeptuneGoal {
    /// The goal on the floor (m), and how near the position model must put the robot.
    pub goal_m: [f64; 2],
    pub goal_tolerance_m: f64,
    /// The longest step between stops (m), and the stillness awaited before a look (s).
    pub step_m: f64,
    pub settle_s: f64,
    /// A look unanswered this long (s) is asked again.
    pub look_timeout_s: f64,
    /// Lucas registration instead of match-then-solve.
    pub lucas: bool,
    /// Obstacles make the path dear within this of their points (a margin) and dearer within
    /// `hard_clearance_m` (the robot's reach); dear, not impassable, so a robot in a margin
    /// plans its way out.
    pub clearance_m: f64,
    pub hard_clearance_m: f64,
    /// What stereo cannot see behind an obstacle's face counts as the obstacle this far on.
    pub shadow_m: f64,
    /// The planning grid's cell (m) and the room's extent (m), which the robot knows.
    pub cell_m: f64,
    pub room_min_m: [f64; 2],
    pub room_max_m: [f64; 2],
    /// Driving between stops: speed (m/s), turn rate (degrees/s) and its gain (per second); a
    /// step's target counts as reached this near (m) and a turn this near (degrees).
    pub speed_mps: f64,
    pub max_turn_degps: f64,
    pub turn_gain: f64,
    pub arrive_m: f64,
    pub aligned_deg: f64,
    /// A wider turn is a step of its own (a stop to look after it), so that two stops' views
    /// share enough features.
    pub max_step_turn_deg: f64,
    /// A step the sonar's panic-stop holds back ends; the robot backs up to this far (m) by its
    /// encoders before it looks, as far as the ring shows the way behind clear, so that the next
    /// path starts outside what held it. At most `step_m`.
    pub back_off_m: f64,
}

pub(crate) fn check_neptune(n: &NeptuneGoal) -> Result<(), &'static str> {
    if n.hard_clearance_m > n.clearance_m {
        return Err("hard_clearance_m is more than clearance_m");
    }
    if (0..2).any(|k| n.room_min_m[k] >= n.room_max_m[k]) {
        return Err("room_min_m is not below room_max_m");
    }
    if (0..2).any(|k| n.goal_m[k] <= n.room_min_m[k] || n.goal_m[k] >= n.room_max_m[k]) {
        return Err("goal_m is outside the room");
    }
    if n.look_timeout_s <= 0.0 {
        return Err("look_timeout_s is not positive");
    }
    if n.arrive_m >= n.step_m {
        return Err("arrive_m is not less than step_m");
    }
    if n.back_off_m > n.step_m {
        return Err("back_off_m is more than step_m");
    }
    Ok(())
}

pub(crate) fn check_ptrans(p: &PtransGoal) -> Result<(), &'static str> {
    let lengths =
        [p.approach_m, p.door_depth_m, p.milestone_m, p.goal_tolerance_m, p.escalate_m, p.back_off_m];
    if !lengths.iter().all(|&v| greater(v, 0.0)) || !p.goal_heading_deg.is_finite() {
        return Err("lengths must be positive and the heading finite");
    }
    if !p.goal_m.iter().all(|v| v.is_finite()) || p.attempts == 0 {
        return Err("goal_m must be finite and attempts at least 1");
    }
    if p.escalate_m <= p.milestone_m.max(p.goal_tolerance_m) {
        return Err("escalate_m must exceed milestone_m and goal_tolerance_m");
    }
    Ok(())
}

pub(crate) fn check_docking(d: &DockingGoal) -> Result<(), &'static str> {
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
        return Err("sizes, ranges, speeds and gains must be positive");
    }
    let finite = [d.dock_m[0], d.dock_m[1], d.dock_facing_deg, d.frame_height_m, d.target_height_m];
    if !(finite.iter().all(|v| v.is_finite()) && d.hough_range_sd_m >= 0.0 && d.noise_mps >= 0.0) {
        return Err("the dock's place and the spreads must be finite");
    }
    if !(0.0..=1.0).contains(&d.hough_min_certainty) || !greater(d.final_m, d.too_close_m) {
        return Err("hough_min_certainty must be in 0..1 and too_close_m under final_m");
    }
    if !(0.0 <= d.target_grey[0] && d.target_grey[0] <= d.target_grey[1] && d.target_grey[1] <= 255.0) {
        return Err("target_grey must be two grey levels, low then high");
    }
    Ok(())
}

pub(crate) fn check_poles(p: &PolesGoal) -> Result<(), &'static str> {
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
        return Err("angles, times, distances, speeds and gains must be positive, past_decay in 0..1");
    }
    if p.count == 0 || p.enough > p.count || !greater(p.lost_m, p.park_m) || !greater(p.near_m, p.park_m) {
        return Err("count at least 1, enough at most count, lost_m and near_m beyond park_m");
    }
    Ok(())
}

fn default_approach_cone_deg() -> f64 {
    30.0
}

fn default_hough_band_min_m() -> f64 {
    0.3
}
