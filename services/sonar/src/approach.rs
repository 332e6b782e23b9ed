//! Approach detection for the panic-avoid (001 §6.2): each sensor's successive time-stamped
//! readings, with the robot's own motion taken out, show whether something is coming at it.
//!
//! A reading `r` along the sensor's axis `u` from the robot at `p` puts the echo at `p + r u`;
//! for a still object `r + p·u` stays constant while the robot drives, so its slope over the
//! sensor's last few readings (a least-squares fit) is the object's own speed towards the robot.
//! The robot's pose at each reading's stamp comes from odometry (interpolated); while the robot
//! turns, the axis sweeps over other things, so a window spanning a turn starts afresh.

use std::collections::VecDeque;

use harvey_msgs::{Odometry, SONAR_SENSORS, SonarRing};

use crate::bearing_rad;

/// Readings in one sensor's fit.
const WINDOW: usize = 4;
/// Odometry poses kept for interpolation.
const POSES: usize = 16;

/// Settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ApproachParams {
    /// Least speed (m/s) of the object itself towards the robot.
    pub min_approach_mps: f64,
    /// Time to contact (s) at or under which an approach counts.
    pub ttc_s: f64,
    /// A window over which the robot turned more than this (radians) starts afresh.
    pub max_turn_rad: f64,
}

#[derive(Debug, Clone, Copy, Default)]
struct Window {
    n: usize,
    /// Reading time (s), compensated range `r + p·u` (m), robot heading (rad).
    t: [f64; WINDOW],
    c: [f64; WINDOW],
    heading: [f64; WINDOW],
    last_stamp: u64,
    /// Consecutive readings that showed an approach within the time to contact.
    streak: u32,
    /// The latest reading showed something coming, however far.
    closing: bool,
}

impl Window {
    fn push(&mut self, t: f64, c: f64, heading: f64) {
        if self.n == WINDOW {
            self.t.copy_within(1.., 0);
            self.c.copy_within(1.., 0);
            self.heading.copy_within(1.., 0);
            self.n -= 1;
        }
        (self.t[self.n], self.c[self.n], self.heading[self.n]) = (t, c, heading);
        self.n += 1;
    }

    /// The least-squares slope of the compensated range (m/s), once the window is full.
    fn slope(&self) -> Option<f64> {
        if self.n < WINDOW {
            return None;
        }
        let (mt, mc) =
            (self.t.iter().sum::<f64>() / WINDOW as f64, self.c.iter().sum::<f64>() / WINDOW as f64);
        let (mut stc, mut stt) = (0.0, 0.0);
        for k in 0..WINDOW {
            stc += (self.t[k] - mt) * (self.c[k] - mc);
            stt += (self.t[k] - mt) * (self.t[k] - mt);
        }
        (stt > 0.0).then(|| stc / stt)
    }
}

/// The detector: odometry history and one window per sensor.
#[derive(Debug)]
pub struct Approach {
    p: ApproachParams,
    poses: VecDeque<(u64, [f64; 3])>,
    windows: [Window; SONAR_SENSORS],
}

impl Approach {
    pub fn new(p: ApproachParams) -> Self {
        Self { p, poses: VecDeque::with_capacity(POSES), windows: [Window::default(); SONAR_SENSORS] }
    }

    pub fn on_odometry(&mut self, o: &Odometry) {
        let (t, w) = (o.header.stamp_ns, o.world_from_robot);
        if self.poses.back().is_some_and(|&(last, _)| last >= t) {
            return;
        }
        if self.poses.len() == POSES {
            self.poses.pop_front();
        }
        self.poses.push_back((t, [w.x_m, w.y_m, w.heading_rad]));
    }

    /// The robot's pose (x, y, heading) at `t`: interpolated between odometry poses, extrapolated
    /// from the last two past the newest.
    fn pose_at(&self, t: u64) -> Option<[f64; 3]> {
        let n = self.poses.len();
        let first = self.poses.front()?;
        if n == 1 || t <= first.0 {
            return Some(first.1);
        }
        let k = self.poses.iter().position(|&(s, _)| s >= t).unwrap_or(n - 1).max(1);
        let ((t0, a), (t1, b)) = (self.poses[k - 1], self.poses[k]);
        let f = (t as f64 - t0 as f64) / (t1 as f64 - t0 as f64);
        Some([0, 1, 2].map(|i| a[i] + f * (b[i] - a[i])))
    }

    /// The robot's velocity (world frame, m/s) from its two newest poses.
    fn velocity(&self) -> [f64; 2] {
        let n = self.poses.len();
        if n < 2 {
            return [0.0; 2];
        }
        let ((t0, a), (t1, b)) = (self.poses[n - 2], self.poses[n - 1]);
        let dt = (t1 - t0) as f64 * 1e-9;
        [(b[0] - a[0]) / dt, (b[1] - a[1]) / dt]
    }

    /// Folds in a ring's new readings; returns the mask of sensors whose latest reading showed
    /// something coming at the robot at least the least approach speed, whatever its time to
    /// contact (the streaks count readings within it).
    pub fn on_ring(&mut self, ring: &SonarRing) -> u32 {
        let mut mask = 0;
        let v = self.velocity();
        for i in 0..SONAR_SENSORS {
            let (r, stamp) = (ring.range_m[i], ring.reading_stamp_ns[i]);
            let valid = ring.valid_mask & (1 << i) != 0 && r.is_finite();
            let Some([x, y, th]) = self.pose_at(stamp) else { continue };
            let w = &mut self.windows[i];
            if !valid {
                *w = Window::default();
                continue;
            }
            if stamp <= w.last_stamp {
                mask |= u32::from(w.closing) << i;
                continue; // no new reading of this sensor
            }
            w.last_stamp = stamp;
            if w.n > 0 && (th - w.heading[0]).abs() > self.p.max_turn_rad {
                *w = Window { last_stamp: stamp, ..Window::default() };
            }
            let dir = th + bearing_rad(i);
            let u = [dir.cos(), dir.sin()];
            w.push(stamp as f64 * 1e-9, f64::from(r) + x * u[0] + y * u[1], th);
            let approach = w.slope().map_or(0.0, |s| -s);
            let closing = approach + v[0] * u[0] + v[1] * u[1];
            w.closing = approach >= self.p.min_approach_mps && closing > 0.0;
            let coming = w.closing && f64::from(r) / closing <= self.p.ttc_s;
            w.streak = if coming { w.streak + 1 } else { 0 };
            mask |= u32::from(w.closing) << i;
        }
        mask
    }

    /// Consecutive readings of sensor `i` that showed an approach.
    pub fn streak(&self, i: usize) -> u32 {
        self.windows[i].streak
    }
}
