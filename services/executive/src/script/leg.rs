//! One straight leg driven in increments (000 §5.5): MOVE an increment; with action-level
//! servoing, look for the landmark from where the robot should now be, take the heading error
//! from its image position, TURN the correction towards a point ahead on the intended line; then
//! the next increment. Without servoing the increments simply follow one another (open loop).

use harvey_msgs::Pose2;

use super::sighting::{Sighted, measure_mount, sighting};
use crate::servo::{ServoParams, correction, correction_off_line, heading_error, heading_error_off_line};

/// How a leg estimates its offset from the intended line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Tracking {
    /// 000 §5.5 as written: each increment starts on the line, its offset is `m sin h`.
    Increment,
    /// The offset summed over the leg's increments, from the measured headings.
    #[default]
    Whole,
}

/// What servoing a leg needs: the landmark point (world, metres) and the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoSetup {
    pub landmark_index: u32,
    /// The point of the landmark the correlation finds (a vertex), in the world.
    pub point: [f64; 3],
    /// Its offset from the landmark's own point (what the vision request carries).
    pub offset: [f64; 3],
    pub params: ServoParams,
    /// Image size (pixels): `x` and `y` are measured from its centre.
    pub width_px: u32,
    pub height_px: u32,
    /// The camera's height above the floor (m): with the landmark point's height, the image row
    /// it is seen in gives its distance.
    pub camera_height_m: f64,
    pub tracking: Tracking,
    /// Measure the camera mount's yaw and pitch before the first increment, from the landmark
    /// seen at the leg's start, where the robot stands on the line heading along it (a
    /// boresight check: the robot does not know its mount exactly).
    pub calibrate: bool,
    /// A sighting implying a heading error beyond `gate_rad`, or a distance off the expected by
    /// more than the fraction `gate_range`, is a false match: taken as a miss (002 §5.2: a
    /// tracked landmark must be where it can be).
    pub gate_rad: f64,
    pub gate_range: f64,
}

/// What the leg wants done next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LegStep {
    Move(f64),
    Turn(f64),
    /// Look for the landmark, expecting it from this pose.
    Look(Pose2),
    Done,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Looking at the landmark from the start, to measure the mount.
    Calibrating,
    Moving,
    Looking,
    Turning,
}

/// The leg's progress.
#[derive(Debug, Clone, PartialEq)]
pub struct Leg {
    /// Where the leg starts and the heading of its intended line.
    pub line: Pose2,
    pub length_m: f64,
    pub increment_m: f64,
    pub servo: Option<ServoSetup>,
    /// Increments commanded so far.
    done: usize,
    phase: Phase,
    /// Heading errors and corrections so far (radians).
    pub corrections: Vec<(f64, f64)>,
    /// Looks that did not find the landmark (refused false matches included).
    pub misses: u32,
    /// Sightings refused as false matches.
    pub refused: u32,
    tracking: Tracking,
    /// Estimated offset from the line (m, left positive) and heading relative to it (radians).
    pub offset_m: f64,
    heading_rad: f64,
    /// How far the robot is behind where its increments should have put it (m): measured from
    /// the landmark's distance (translational loss, 002 Table 3).
    pub shortfall_m: f64,
    /// The camera mount's yaw (left positive) and pitch (down positive), radians: as
    /// configured, or as measured at the start.
    pub mount_rad: (f64, f64),
}

impl Leg {
    pub fn new(line: Pose2, length_m: f64, increment_m: f64, servo: Option<ServoSetup>) -> Self {
        Self {
            line,
            length_m,
            increment_m,
            servo,
            done: 0,
            phase: Phase::Moving,
            corrections: Vec::new(),
            misses: 0,
            refused: 0,
            tracking: servo.map_or(Tracking::Whole, |s| s.tracking),
            offset_m: 0.0,
            heading_rad: 0.0,
            shortfall_m: 0.0,
            mount_rad: (servo.map_or(0.0, |s| s.params.misalignment_rad), 0.0),
        }
    }

    fn increments(&self) -> usize {
        (self.length_m / self.increment_m - 1e-9).ceil().max(1.0) as usize
    }

    /// Length of increment `k` (the last one takes what is left).
    fn increment(&self, k: usize) -> f64 {
        (self.length_m - k as f64 * self.increment_m).min(self.increment_m)
    }

    /// Where the robot should be after `k` increments: on the line, heading along it.
    pub fn expected(&self, k: usize) -> Pose2 {
        let d = (k as f64 * self.increment_m).min(self.length_m) - self.shortfall_m;
        self.line.arc(d, 0.0)
    }

    /// Whether the look asked for is the first, measuring the mount: discovery (002 §5.2) where
    /// any mount within its tolerance can put the landmark (`window::first_look_window`), where
    /// later looks track it in the window the gates allow.
    pub fn discovering(&self) -> bool {
        self.phase == Phase::Calibrating
    }

    /// Increments commanded so far.
    pub fn increments_done(&self) -> usize {
        self.done
    }

    /// The first step.
    pub fn start(&mut self) -> LegStep {
        if self.servo.is_some_and(|s| s.calibrate) {
            self.phase = Phase::Calibrating;
            return LegStep::Look(self.line);
        }
        self.phase = Phase::Moving;
        self.done = 1;
        LegStep::Move(self.increment(0))
    }

    /// A reflex took the robot from the leg's start before its first look measured the mount:
    /// back there by odometry, its heading is not the line's, and a mount measured from it would
    /// take the difference for the mount's yaw. The mount stays as configured; the first
    /// increment follows.
    pub fn skip_calibration(&mut self) -> LegStep {
        self.misses += 1;
        self.phase = Phase::Moving;
        self.done = 1;
        LegStep::Move(self.increment(0))
    }

    /// The last MOVE or TURN finished.
    pub fn on_done(&mut self) -> LegStep {
        match (self.phase, self.servo) {
            (Phase::Moving, Some(_)) => {
                self.phase = Phase::Looking;
                LegStep::Look(self.expected(self.done))
            }
            _ => self.next_move(),
        }
    }

    /// The look's outcome: the landmark's image position `[u, v]` (pixels), or `None` when it
    /// was not found.
    pub fn on_seen(&mut self, seen: Option<[f64; 2]>) -> LegStep {
        if self.phase == Phase::Calibrating {
            if let (Some(s), Some(uv)) = (self.servo, seen) {
                self.mount_rad = measure_mount(&s, self.line, uv);
            } else {
                self.misses += 1;
            }
            self.phase = Phase::Moving;
            self.done = 1;
            return LegStep::Move(self.increment(0));
        }
        let (Some(s), Some(uv)) = (self.servo, seen) else {
            self.misses += u32::from(seen.is_none());
            return self.next_move();
        };
        // The landmark in the frame of the intended line at the expected position.
        let e = self.expected(self.done);
        let sighted = match sighting(&s, e, self.mount_rad, self.offset_m, uv) {
            Ok(sighted) => sighted,
            Err((bearing_error, range_error_m)) => return self.false_match(bearing_error, range_error_m),
        };
        let Sighted { landmark, x_left, params, range_error_m } = sighted;
        self.shortfall_m += range_error_m.unwrap_or(0.0);
        let m = self.increment(self.done - 1);
        let (h, turn) = match self.tracking {
            // 000 §5.5 as written: the increment started on the line.
            Tracking::Increment => {
                let h = heading_error(landmark, x_left, m, &params);
                (h, correction(h, m, &params))
            }
            // The offset carried over from earlier increments too: the increment ran at the
            // mean of its start heading (the last one corrected) and its end heading.
            Tracking::Whole => {
                let mut h = heading_error_off_line(landmark, x_left, self.offset_m, &params);
                for _ in 0..2 {
                    let off = self.offset_m + m * ((self.heading_rad + h) / 2.0).sin();
                    h = heading_error_off_line(landmark, x_left, off, &params);
                }
                self.offset_m += m * ((self.heading_rad + h) / 2.0).sin();
                (h, correction_off_line(h, self.offset_m, &params))
            }
        };
        self.heading_rad = h + turn;
        self.corrections.push((h, turn));
        if self.done >= self.increments() {
            return LegStep::Done;
        }
        self.phase = Phase::Turning;
        LegStep::Turn(turn)
    }

    /// A sighting no believable pose explains: counted as a miss, no correction.
    fn false_match(&mut self, bearing_error: f64, range_error_m: Option<f64>) -> LegStep {
        tracing::info!(
            bearing_error_deg = bearing_error.to_degrees(),
            range_error_m,
            "servo sighting refused as a false match"
        );
        self.misses += 1;
        self.refused += 1;
        self.next_move()
    }

    fn next_move(&mut self) -> LegStep {
        if self.done >= self.increments() {
            return LegStep::Done;
        }
        self.phase = Phase::Moving;
        self.done += 1;
        LegStep::Move(self.increment(self.done - 1))
    }
}

/// The tests' servoing set-up: a landmark 16 m down the line, 0.2 m to its left, at the
/// camera's height (also the script runner's tests').
#[cfg(test)]
pub(crate) fn test_setup() -> ServoSetup {
    ServoSetup {
        landmark_index: 7,
        point: [16.0, 0.2, 2.3],
        offset: [0.0, 0.2, 0.1],
        params: ServoParams { focal_px: 554.0, misalignment_rad: 0.0, aim_m: 1.2 },
        width_px: 640,
        height_px: 480,
        camera_height_m: 2.3,
        tracking: Tracking::Increment,
        calibrate: false,
        gate_rad: 3f64.to_radians(),
        gate_range: 0.1,
    }
}

#[cfg(test)]
mod tests;
