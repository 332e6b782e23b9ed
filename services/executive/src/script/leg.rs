//! One straight leg driven in increments (000 §5.5): MOVE an increment; with action-level
//! servoing, look for the landmark from where the robot should now be, take the heading error
//! from its image position, TURN the correction towards a point ahead on the intended line; then
//! the next increment. Without servoing the increments simply follow one another (open loop).

use harvey_msgs::Pose2;

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
    /// Looks that did not find the landmark.
    pub misses: u32,
    tracking: Tracking,
    /// Estimated offset from the line (m, left positive) and heading relative to it (radians).
    pub offset_m: f64,
    heading_rad: f64,
    /// How far the robot is behind where its increments should have put it (m): measured from
    /// the landmark's distance (translational loss, 002 Table 3).
    pub shortfall_m: f64,
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
            tracking: servo.map_or(Tracking::Whole, |s| s.tracking),
            offset_m: 0.0,
            heading_rad: 0.0,
            shortfall_m: 0.0,
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

    /// Increments commanded so far.
    pub fn increments_done(&self) -> usize {
        self.done
    }

    /// The first step.
    pub fn start(&mut self) -> LegStep {
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
        let (Some(s), Some([u, v])) = (self.servo, seen) else {
            self.misses += u32::from(seen.is_none());
            return self.next_move();
        };
        // The landmark in the frame of the intended line at the expected position.
        let e = self.expected(self.done);
        let (c, sn) = (e.heading_rad.cos(), e.heading_rad.sin());
        let (dx, dy) = (s.point[0] - e.x_m, s.point[1] - e.y_m);
        let mut landmark = [dx * c + dy * sn, -dx * sn + dy * c];
        // Its distance from the row it is seen in, where it stands well above or below the camera.
        let (dz, rise) = (s.point[2] - s.camera_height_m, f64::from(s.height_px) / 2.0 - v);
        if dz.abs() > 0.2 && rise * dz > 0.0 && rise.abs() > 2.0 {
            let measured = dz * s.params.focal_px / rise;
            self.shortfall_m -= landmark[0] - measured;
            landmark[0] = measured;
        }
        let x_left = f64::from(s.width_px) / 2.0 - u;
        let m = self.increment(self.done - 1);
        let (h, turn) = match self.tracking {
            // 000 §5.5 as written: the increment started on the line.
            Tracking::Increment => {
                let h = heading_error(landmark, x_left, m, &s.params);
                (h, correction(h, m, &s.params))
            }
            // The offset carried over from earlier increments too: the increment ran at the
            // mean of its start heading (the last one corrected) and its end heading.
            Tracking::Whole => {
                let mut h = heading_error_off_line(landmark, x_left, self.offset_m, &s.params);
                for _ in 0..2 {
                    let off = self.offset_m + m * ((self.heading_rad + h) / 2.0).sin();
                    h = heading_error_off_line(landmark, x_left, off, &s.params);
                }
                self.offset_m += m * ((self.heading_rad + h) / 2.0).sin();
                (h, correction_off_line(h, self.offset_m, &s.params))
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup() -> ServoSetup {
        test_setup()
    }

    #[test]
    fn an_open_loop_leg_is_its_increments() {
        let mut leg = Leg::new(Pose2::default(), 1.5, 0.6, None);
        assert_eq!(leg.start(), LegStep::Move(0.6));
        assert_eq!(leg.on_done(), LegStep::Move(0.6));
        let LegStep::Move(last) = leg.on_done() else { panic!("a third increment") };
        assert!((last - 0.3).abs() < 1e-12);
        assert_eq!(leg.on_done(), LegStep::Done);
    }

    #[test]
    fn a_servoed_leg_looks_after_each_increment_and_turns_the_correction() {
        let mut leg = Leg::new(Pose2::default(), 1.2, 0.6, Some(setup()));
        assert_eq!(leg.start(), LegStep::Move(0.6));
        let LegStep::Look(at) = leg.on_done() else { panic!("looks") };
        assert!((at.x_m - 0.6).abs() < 1e-12 && at.y_m == 0.0);
        // Seen where expected from the line (x left = f * 0.2 / 15.4): no heading error.
        let u = 320.0 - 554.0 * (0.2f64 / 15.4);
        let LegStep::Turn(t) = leg.on_seen(Some([u, 240.0])) else { panic!("turns") };
        assert!(t.abs() < 1e-9, "{t}");
        assert_eq!(leg.on_done(), LegStep::Move(0.6));
        // Seen 10 px right of where expected: the robot is turned left; it turns back right.
        let LegStep::Look(_) = leg.on_done() else { panic!("looks") };
        let u = 320.0 - 554.0 * (0.2f64 / 14.8) + 10.0;
        assert_eq!(leg.on_seen(Some([u, 240.0])), LegStep::Done, "the last increment ends the leg");
        let (h, turn) = leg.corrections[1];
        assert!(h > 0.0 && turn < 0.0 && (h - (10.0f64 / 554.0).atan()).abs() < 2e-3, "{h} {turn}");
        // A miss skips the correction.
        let mut leg = Leg::new(Pose2::default(), 1.2, 0.6, Some(setup()));
        leg.start();
        leg.on_done();
        assert_eq!(leg.on_seen(None), LegStep::Move(0.6));
        assert_eq!(leg.misses, 1);
    }
}
