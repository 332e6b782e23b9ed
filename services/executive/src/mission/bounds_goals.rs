//! The ranges of the goal tables' numbers (`[mission.ptrans]`, `[mission.docking]`,
//! `[mission.poles]`, `[mission.neptune]`): finite and inside what the behaviours can do, checked before the
//! tables' own checks of how their numbers fit together (`goals.rs`).

use super::bounds::{ANGLE, LENGTH, LENGTH_OR_ZERO, POSITION, TIMEOUT};
use super::goals::{DockingGoal, NeptuneGoal, PolesGoal, PtransGoal};
use harvey_config::range::{OutOfRange, Range, check, check_all, check_int};
use harvey_config::spans::KeyPath;

/// Sizes and heights of things on the floor (the dock's frame and target): the world's walls and
/// poles are at most 100 m high. A centre's height may be on the floor, not below it.
const SIZE: Range = Range::above(0.0, 100.0, "m");
const HEIGHT: Range = Range::closed(0.0, 100.0, "m");
/// Grey levels of an 8-bit image.
const GREY: Range = Range::closed(0.0, 255.0, "");
/// Fractions (a certainty, a decay per tick).
const FRACTION: Range = Range::closed(0.0, 1.0, "");
/// How many times its background ring tape must be (the vision workers refuse beyond 1..=4).
const RING_CONTRAST: Range = Range::closed(1.0, 4.0, "");
/// An area in the image: positive, up to the largest image the world's camera renders
/// (4096 x 4096 px).
const AREA_PX: Range = Range::above(0.0, 16_777_216.0, "px");
/// Angles the behaviours keep within or sweep (bearings, gates): positive, up to half a turn;
/// a sweep up to a whole turn.
pub(crate) const HALF_TURN: Range = Range::above(0.0, 180.0, "deg");
const SWEEP: Range = Range::above(0.0, 360.0, "deg");
/// Speeds: positive, up to the world's fastest robot (10 m/s); the schemas' gains and the noise
/// are speeds too, and may be zero (the schema left out).
pub(crate) const SPEED: Range = Range::above(0.0, 10.0, "m/s");
pub(crate) const GAIN: Range = Range::closed(0.0, 10.0, "m/s");
/// The turn rate limit: positive, up to the world's fastest turn (360 deg/s); its gain positive
/// and at most 100 per second (a tenth of a tick's correction at 1 kHz).
pub(crate) const TURN_RATE: Range = Range::above(0.0, 360.0, "deg/s");
pub(crate) const TURN_GAIN: Range = Range::above(0.0, 100.0, "per s");
/// Waits that may be zero: no longer than the longest mission.
pub(crate) const WAIT: Range = Range::closed(0.0, TIMEOUT.hi, "s");
/// Counts of ticks (a fix's period, the noise's persistence): up to a million, more than a
/// day-long mission has at 10 Hz; a tick counter never overflows.
const MAX_TICKS: u32 = 1_000_000;
/// Replans and retries of a milestone: up to a thousand (each is a plan developed afresh).
const MAX_ATTEMPTS: u32 = 1_000;
/// Poles of an arena: the world crate's cap on `[poles] count`.
const MAX_POLES: u32 = 100;

pub(crate) fn check_neptune(k: &KeyPath, n: &NeptuneGoal) -> Result<(), OutOfRange> {
    check_all(&k.key("goal_m"), &n.goal_m, &POSITION)?;
    check(&k.key("goal_tolerance_m"), n.goal_tolerance_m, &LENGTH)?;
    check(&k.key("step_m"), n.step_m, &LENGTH)?;
    check(&k.key("settle_s"), n.settle_s, &WAIT)?;
    check(&k.key("look_timeout_s"), n.look_timeout_s, &WAIT)?;
    check(&k.key("clearance_m"), n.clearance_m, &SIZE)?;
    check(&k.key("hard_clearance_m"), n.hard_clearance_m, &SIZE)?;
    check(&k.key("shadow_m"), n.shadow_m, &HEIGHT)?;
    // A planning cell: at least a centimetre (the grid is capped at 2000 cells a side).
    check(&k.key("cell_m"), n.cell_m, &Range::closed(0.01, 10.0, "m"))?;
    check_all(&k.key("room_min_m"), &n.room_min_m, &POSITION)?;
    check_all(&k.key("room_max_m"), &n.room_max_m, &POSITION)?;
    check(&k.key("speed_mps"), n.speed_mps, &SPEED)?;
    check(&k.key("max_turn_degps"), n.max_turn_degps, &TURN_RATE)?;
    check(&k.key("turn_gain"), n.turn_gain, &TURN_GAIN)?;
    check(&k.key("arrive_m"), n.arrive_m, &LENGTH)?;
    check(&k.key("aligned_deg"), n.aligned_deg, &HALF_TURN)?;
    check(&k.key("max_step_turn_deg"), n.max_step_turn_deg, &HALF_TURN)?;
    check(&k.key("back_off_m"), n.back_off_m, &LENGTH)
}

pub(crate) fn check_ptrans(k: &KeyPath, p: &PtransGoal) -> Result<(), OutOfRange> {
    check_all(&k.key("goal_m"), &p.goal_m, &POSITION)?;
    check(&k.key("goal_heading_deg"), p.goal_heading_deg, &ANGLE)?;
    check(&k.key("approach_m"), p.approach_m, &LENGTH)?;
    check(&k.key("door_depth_m"), p.door_depth_m, &LENGTH)?;
    check(&k.key("milestone_m"), p.milestone_m, &LENGTH)?;
    check(&k.key("goal_tolerance_m"), p.goal_tolerance_m, &LENGTH)?;
    check(&k.key("escalate_m"), p.escalate_m, &LENGTH)?;
    check_int(&k.key("attempts"), p.attempts, 1, MAX_ATTEMPTS, "")?;
    check(&k.key("back_off_m"), p.back_off_m, &LENGTH)
}

pub(crate) fn check_docking(k: &KeyPath, d: &DockingGoal) -> Result<(), OutOfRange> {
    check_all(&k.key("dock_m"), &d.dock_m, &POSITION)?;
    check(&k.key("dock_facing_deg"), d.dock_facing_deg, &ANGLE)?;
    check(&k.key("frame_width_m"), d.frame_width_m, &SIZE)?;
    check(&k.key("frame_height_m"), d.frame_height_m, &HEIGHT)?;
    check(&k.key("target_side_m"), d.target_side_m, &SIZE)?;
    check(&k.key("target_height_m"), d.target_height_m, &HEIGHT)?;
    check_all(&k.key("target_grey"), &d.target_grey, &GREY)?;
    check(&k.key("light_contrast"), d.light_contrast, &Range::closed(1.0, 255.0, "x"))?;
    check(&k.key("lamp_area_m2"), d.lamp_area_m2, &Range::above(0.0, 100.0, "m2"))?;
    check(&k.key("light_near_m"), d.light_near_m, &LENGTH)?;
    check(&k.key("hough_range_m"), d.hough_range_m, &LENGTH)?;
    check(&k.key("hough_range_sd_m"), d.hough_range_sd_m, &LENGTH_OR_ZERO)?;
    check(&k.key("hough_min_certainty"), d.hough_min_certainty, &FRACTION)?;
    check(&k.key("hough_band_min_m"), d.hough_band_min_m, &Range::closed(0.0, 5.0, "m"))?;
    check(&k.key("retry_after_m"), d.retry_after_m, &LENGTH)?;
    check(&k.key("lead_m"), d.lead_m, &LENGTH)?;
    check(&k.key("keep_in_view_deg"), d.keep_in_view_deg, &HALF_TURN)?;
    check(&k.key("approach_cone_deg"), d.approach_cone_deg, &Range::above(0.0, 90.0, "deg"))?;
    check(&k.key("close_area_px"), d.close_area_px, &AREA_PX)?;
    check_int(&k.key("fix_every_ticks"), d.fix_every_ticks, 0, MAX_TICKS, "ticks")?;
    check(&k.key("fix_beyond_m"), d.fix_beyond_m, &LENGTH_OR_ZERO)?;
    check(&k.key("fix_gate_m"), d.fix_gate_m, &LENGTH)?;
    check(&k.key("fix_gate_deg"), d.fix_gate_deg, &HALF_TURN)?;
    check(&k.key("post_height_sd_px"), d.post_height_sd_px, &Range::above(0.0, 100.0, "px"))?;
    check(&k.key("heading_drift_deg_per_m"), d.heading_drift_deg_per_m, &Range::above(0.0, 90.0, "deg/m"))?;
    check(&k.key("final_m"), d.final_m, &LENGTH)?;
    check(&k.key("too_close_m"), d.too_close_m, &LENGTH_OR_ZERO)?;
    check(&k.key("ballistic_mps"), d.ballistic_mps, &SPEED)?;
    check(&k.key("controlled_mps"), d.controlled_mps, &SPEED)?;
    check(&k.key("max_turn_degps"), d.max_turn_degps, &TURN_RATE)?;
    check(&k.key("turn_gain"), d.turn_gain, &TURN_GAIN)?;
    check(&k.key("avoid_sphere_m"), d.avoid_sphere_m, &LENGTH)?;
    check(&k.key("avoid_gain"), d.avoid_gain, &GAIN)?;
    check(&k.key("noise_mps"), d.noise_mps, &GAIN)?;
    check_int(&k.key("noise_ticks"), d.noise_ticks, 0, MAX_TICKS, "ticks")
}

pub(crate) fn check_poles(k: &KeyPath, p: &PolesGoal) -> Result<(), OutOfRange> {
    check_int(&k.key("count"), p.count, 1, MAX_POLES, "poles")?;
    check_int(&k.key("enough"), p.enough, 0, MAX_POLES, "poles")?;
    check(&k.key("sweep_deg"), p.sweep_deg, &SWEEP)?;
    check(&k.key("centred_deg"), p.centred_deg, &HALF_TURN)?;
    check(&k.key("wander_s"), p.wander_s, &TIMEOUT)?;
    check(&k.key("ring_contrast"), p.ring_contrast, &RING_CONTRAST)?;
    check(&k.key("near_m"), p.near_m, &LENGTH)?;
    check(&k.key("timer_slack_s"), p.timer_slack_s, &WAIT)?;
    check(&k.key("beacon_wait_s"), p.beacon_wait_s, &WAIT)?;
    check(&k.key("back_off_s"), p.back_off_s, &WAIT)?;
    check(&k.key("park_m"), p.park_m, &LENGTH)?;
    check(&k.key("lost_m"), p.lost_m, &LENGTH)?;
    check(&k.key("lost_after_s"), p.lost_after_s, &WAIT)?;
    check(&k.key("ballistic_mps"), p.ballistic_mps, &SPEED)?;
    check(&k.key("controlled_mps"), p.controlled_mps, &SPEED)?;
    check(&k.key("max_turn_degps"), p.max_turn_degps, &TURN_RATE)?;
    check(&k.key("turn_gain"), p.turn_gain, &TURN_GAIN)?;
    check(&k.key("avoid_sphere_m"), p.avoid_sphere_m, &LENGTH)?;
    check(&k.key("avoid_gain"), p.avoid_gain, &GAIN)?;
    check(&k.key("probe_gain"), p.probe_gain, &GAIN)?;
    check(&k.key("past_gain"), p.past_gain, &GAIN)?;
    check(&k.key("past_cell_m"), p.past_cell_m, &LENGTH)?;
    check(&k.key("past_decay"), p.past_decay, &FRACTION)?;
    check(&k.key("noise_mps"), p.noise_mps, &GAIN)?;
    check_int(&k.key("noise_ticks"), p.noise_ticks, 0, MAX_TICKS, "ticks")
}
