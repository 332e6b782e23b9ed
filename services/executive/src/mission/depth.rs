//! The goal table of obstacle avoidance by depth from motion (`[mission.depth]`, 001 §2.3):
//! where to go, how the robot stops and looks on its straight runs, which tracked points count
//! as obstacles, and how the motor schemas weigh them; the ranges of its numbers.

use harvey_config::range::{OutOfRange, Range, check, check_all};
use harvey_config::spans::KeyPath;
use serde::Deserialize;

use super::bounds::{LENGTH, LENGTH_OR_ZERO, POSITION};
use super::bounds_goals::{GAIN, SPEED, TURN_GAIN, TURN_RATE, WAIT};

/// `[mission.depth]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepthGoal {
    /// The goal on the floor (m) and how near the odometry must put the robot.
    pub goal_m: [f64; 2],
    pub goal_tolerance_m: f64,
    /// A run is straight, in steps of `step_m` between stops, of at most `frames` looks; the
    /// stillness awaited before each look (s); a look unanswered this long (s) ends the run.
    pub step_m: f64,
    pub frames: u32,
    pub settle_s: f64,
    pub look_timeout_s: f64,
    /// The window the run's points are found in at its first look (px: left, top, right,
    /// bottom); its top comes no higher than the row where the floor lies twice `max_range_m`
    /// off.
    pub window_px: [f64; 4],
    /// The tracker: the least correlation score, the Moravec threshold, most points, the
    /// position noise (px).
    pub min_score: f64,
    pub moravec_threshold: f64,
    pub max_points: u32,
    pub noise_px: f64,
    /// A point is an obstacle once it stands off the floor, has been matched in `min_frames`
    /// frames, its depth's spread is at most `max_rel_sd` of it and it is between `min_range_m`
    /// and `max_range_m` away (nearer, what the camera's points say is the sonar's to judge).
    pub min_frames: u32,
    pub max_rel_sd: f64,
    /// (Absent in launch files recorded before it: 0, any depth, as they ran.)
    #[serde(default)]
    pub min_range_m: f64,
    pub max_range_m: f64,
    /// The motor schemas (001 §3.1): move-to-goal's gain (m/s); avoid-static-obstacle round each
    /// obstacle (its points linked within `link_m`) from its nearest point, of radius
    /// `point_radius_m` beyond the robot's, its sphere of influence (m) and gain (m/s). A run
    /// ends, and the robot turns to the schemas' sum, once the sum points more than
    /// `replan_deg` away from the run's heading.
    pub goal_gain: f64,
    pub link_m: f64,
    pub point_radius_m: f64,
    pub sphere_m: f64,
    pub avoid_gain: f64,
    pub replan_deg: f64,
    /// The robot heads no further round than this from the goal (degrees): an obstacle dead
    /// ahead would turn the schemas' sum backwards.
    pub max_detour_deg: f64,
    /// Sonar echoes this near the ring (m) repel as obstacle points too: what is too thin for
    /// the camera's points (a lamppost) and has come close.
    pub sonar_reach_m: f64,
    /// Driving: speed (m/s), turn rate (degrees/s) and its gain (per second); a turn counts as
    /// done this near (degrees).
    pub speed_mps: f64,
    pub max_turn_degps: f64,
    pub turn_gain: f64,
    pub aligned_deg: f64,
}

const PIXELS: Range = Range::closed(0.0, 8192.0, "px");
const FRACTION: Range = Range::closed(0.0, 1.0, "");
const QUARTER_TURN: Range = Range::closed(0.0, 90.0, "deg");
const COUNT: Range = Range::closed(1.0, 10_000.0, "");

pub(crate) fn check_bounds(k: &KeyPath, d: &DepthGoal) -> Result<(), OutOfRange> {
    check_all(&k.key("goal_m"), &d.goal_m, &POSITION)?;
    check(&k.key("goal_tolerance_m"), d.goal_tolerance_m, &LENGTH)?;
    check(&k.key("step_m"), d.step_m, &LENGTH)?;
    check(&k.key("frames"), f64::from(d.frames), &COUNT)?;
    check(&k.key("settle_s"), d.settle_s, &WAIT)?;
    check(&k.key("look_timeout_s"), d.look_timeout_s, &WAIT)?;
    check_all(&k.key("window_px"), &d.window_px, &PIXELS)?;
    check(&k.key("min_score"), d.min_score, &FRACTION)?;
    check(&k.key("moravec_threshold"), d.moravec_threshold, &Range::closed(1.0, 1e9, ""))?;
    check(&k.key("max_points"), f64::from(d.max_points), &COUNT)?;
    check(&k.key("noise_px"), d.noise_px, &Range::above(0.0, 100.0, "px"))?;
    check(&k.key("min_frames"), f64::from(d.min_frames), &COUNT)?;
    check(&k.key("max_rel_sd"), d.max_rel_sd, &FRACTION)?;
    check(&k.key("min_range_m"), d.min_range_m, &LENGTH_OR_ZERO)?;
    check(&k.key("max_range_m"), d.max_range_m, &LENGTH)?;
    check(&k.key("goal_gain"), d.goal_gain, &GAIN)?;
    check(&k.key("link_m"), d.link_m, &LENGTH)?;
    check(&k.key("point_radius_m"), d.point_radius_m, &LENGTH)?;
    check(&k.key("sphere_m"), d.sphere_m, &LENGTH)?;
    check(&k.key("avoid_gain"), d.avoid_gain, &GAIN)?;
    check(&k.key("replan_deg"), d.replan_deg, &QUARTER_TURN)?;
    check(&k.key("sonar_reach_m"), d.sonar_reach_m, &LENGTH)?;
    check(&k.key("max_detour_deg"), d.max_detour_deg, &Range::closed(0.0, 180.0, "deg"))?;
    check(&k.key("speed_mps"), d.speed_mps, &SPEED)?;
    check(&k.key("max_turn_degps"), d.max_turn_degps, &TURN_RATE)?;
    check(&k.key("turn_gain"), d.turn_gain, &TURN_GAIN)?;
    check(&k.key("aligned_deg"), d.aligned_deg, &QUARTER_TURN)
}

pub(crate) fn check_depth(d: &DepthGoal) -> Result<(), &'static str> {
    let [l, t, r, b] = d.window_px;
    if r <= l || b <= t {
        return Err("window_px must run left to right and top to bottom");
    }
    if d.step_m <= 0.0
        || d.speed_mps <= 0.0
        || d.sphere_m <= 0.0
        || d.goal_tolerance_m <= 0.0
        || d.look_timeout_s <= 0.0
    {
        return Err("step_m, speed_mps, sphere_m, goal_tolerance_m and look_timeout_s must be above zero");
    }
    if d.min_range_m >= d.max_range_m {
        return Err("min_range_m must be below max_range_m");
    }
    if d.frames < 2 || d.min_frames < 2 {
        return Err("frames and min_frames must be at least 2: depth needs two looks");
    }
    Ok(())
}
