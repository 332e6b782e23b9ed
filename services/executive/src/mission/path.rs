//! The goal table of path following (`[mission.path]`, 001 §2.1): the path's segments as pairs of
//! class III edge landmarks of the world, how the line finder's fragments are grouped into edges,
//! and how the robot servos on the centreline; the ranges of its numbers.

use harvey_config::range::{OutOfRange, Range, check};
use harvey_config::spans::KeyPath;
use serde::Deserialize;

use super::bounds::LENGTH;
use super::bounds_goals::{SPEED, TURN_GAIN, TURN_RATE};

/// `[mission.path]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathGoal {
    /// The path's segments in the order driven, each its left and right edges (class III
    /// landmarks of the world, both running in the direction of travel): the centreline runs
    /// between their ends, and the robot turns on the spot where one segment's centreline meets
    /// the next.
    pub segments: Vec<[String; 2]>,
    /// The robot stops this far before the last segment's end (m).
    pub stop_before_end_m: f64,
    /// Speed along the path (m/s); turning rate at most (degrees/s) and its gain (per second); a
    /// turn at a bend counts as done this near (degrees).
    pub speed_mps: f64,
    pub max_turn_degps: f64,
    pub turn_gain: f64,
    pub aligned_deg: f64,
    /// The robot steers for the point of the centreline this far ahead of it (m).
    pub lookahead_m: f64,
    /// The line finder's window starts this many rows below the horizon (px): the path's far
    /// end, crowded into a few rows, is left out.
    pub below_horizon_px: f64,
    /// Approaching a bend, the window ends `bend_margin_m` short of it (the next segment's edges
    /// kept out), and fits are not steered by once that leaves less than `least_depth_m` of the
    /// path in view (m).
    pub bend_margin_m: f64,
    pub least_depth_m: f64,
    /// Grouping (001 §2.1): a fragment belongs to an edge when its middle lies within
    /// `max_distance_px` of the predicted edge and its direction within `max_angle_deg`; a fit
    /// needs `min_confidence_px` of fragments in all.
    pub max_distance_px: f64,
    pub max_angle_deg: f64,
    pub min_confidence_px: f64,
    /// A fit whose edges lie further apart on the ground than the map's width times 1 ±
    /// `width_tolerance` is not the path (a lawn's edge taken for it).
    pub width_tolerance: f64,
    /// Without a fit the robot could steer by for this much travel, the workers' tracker starts
    /// afresh from the map and the UMS's pose (once per as much travel), and the path counts as
    /// lost, and the mission as failed, after `lost_after_m` (m).
    pub restart_after_m: f64,
    pub lost_after_m: f64,
}

/// Most segments a path may have.
const MAX_SEGMENTS: usize = 1_000;
const PIXELS: Range = Range::closed(0.0, 4096.0, "px");
const FRACTION: Range = Range::closed(0.0, 1.0, "");
const QUARTER_TURN: Range = Range::closed(0.0, 90.0, "deg");

pub(crate) fn check_bounds(k: &KeyPath, p: &PathGoal) -> Result<(), OutOfRange> {
    check(&k.key("stop_before_end_m"), p.stop_before_end_m, &LENGTH)?;
    check(&k.key("speed_mps"), p.speed_mps, &SPEED)?;
    check(&k.key("max_turn_degps"), p.max_turn_degps, &TURN_RATE)?;
    check(&k.key("turn_gain"), p.turn_gain, &TURN_GAIN)?;
    check(&k.key("aligned_deg"), p.aligned_deg, &QUARTER_TURN)?;
    check(&k.key("lookahead_m"), p.lookahead_m, &LENGTH)?;
    check(&k.key("below_horizon_px"), p.below_horizon_px, &PIXELS)?;
    check(&k.key("bend_margin_m"), p.bend_margin_m, &LENGTH)?;
    check(&k.key("least_depth_m"), p.least_depth_m, &LENGTH)?;
    check(&k.key("max_distance_px"), p.max_distance_px, &PIXELS)?;
    check(&k.key("max_angle_deg"), p.max_angle_deg, &QUARTER_TURN)?;
    check(&k.key("min_confidence_px"), p.min_confidence_px, &PIXELS)?;
    check(&k.key("width_tolerance"), p.width_tolerance, &FRACTION)?;
    check(&k.key("restart_after_m"), p.restart_after_m, &LENGTH)?;
    check(&k.key("lost_after_m"), p.lost_after_m, &LENGTH)
}

pub(crate) fn check_path(p: &PathGoal) -> Result<(), &'static str> {
    if p.segments.is_empty() || p.segments.len() > MAX_SEGMENTS {
        return Err("segments lists no segment, or more than 1000");
    }
    if p.below_horizon_px < 1.0 {
        return Err("below_horizon_px must be at least 1: the horizon's row sees no ground");
    }
    if p.speed_mps <= 0.0 || p.lookahead_m <= 0.0 || p.max_distance_px <= 0.0 || p.max_angle_deg <= 0.0 {
        return Err("speed_mps, lookahead_m, max_distance_px and max_angle_deg must be above zero");
    }
    Ok(())
}
