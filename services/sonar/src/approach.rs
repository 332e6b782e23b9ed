//! Approach detection for the panic-avoid (001 §6.2): each sensor's successive time-stamped
//! readings, with the robot's own motion taken out, show whether something is coming at it.
//!
//! A reading `r` along the sensor's axis `u` from the robot at `p` puts the echo at `p + r u`;
//! for a still object `r + (p - q)·u` stays constant while the robot drives (`q` any fixed point:
//! the newest reading's pose, so that small turns far from the world's origin do not swing it),
//! so its slope over the sensor's last few readings (a least-squares fit) is the object's own
//! speed towards the robot.
//! The robot's pose at each reading's stamp comes from odometry (interpolated); while the robot
//! turns, the axis sweeps over other things, so a window spanning a turn starts afresh, as does
//! one whose range jumps (another surface).
//! A streak of readings confirms an approach only while the object keeps coming: each reading
//! after the first must be nearer than the streak's first by half the fitted approach speed
//! (at least the least approach speed) over the time between, halfway between what a step and
//! what a ramp would show. A smaller step onto a nearer surface tilts the fit of every window
//! that holds it (three in a row, with four readings a window), but the readings after the
//! step come no closer.

use std::collections::VecDeque;

use harvey_msgs::{Odometry, Pose2, SONAR_SENSORS, SonarRing};

use crate::bearing_rad;

/// Readings in one sensor's fit.
const WINDOW: usize = 4;
/// Odometry poses kept for interpolation.
const POSES: usize = 16;
/// A compensated range that jumps by more than this from the sensor's last is another surface
/// (the beam slid off an edge, or a specular wall fell silent): the window starts afresh. A
/// reading comes every 0.15 s, so only something closing at over 2 m/s moves this far between.
const MAX_STEP_M: f64 = 0.3;

/// Settings.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ApproachParams {
    /// Least speed (m/s) of the object itself towards the robot.
    pub min_approach_mps: f64,
    /// Time to contact (s) at or under which an approach counts.
    pub ttc_s: f64,
    /// A window over which the robot turned more than this (radians) starts afresh.
    pub max_turn_rad: f64,
}

/// One reading: its time (s), range (m), the robot's position (m) and the sensor's axis.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
struct Reading {
    t: f64,
    r: f64,
    p: [f64; 2],
    u: [f64; 2],
    heading: f64,
}

impl Reading {
    /// The range compensated for the robot's motion since `q`: `r + (p - q)·u`.
    fn compensated(&self, q: [f64; 2]) -> f64 {
        self.r + (self.p[0] - q[0]) * self.u[0] + (self.p[1] - q[1]) * self.u[1]
    }
}

#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
struct Window {
    n: usize,
    readings: [Reading; WINDOW],
    last_stamp: u64,
    /// Consecutive readings that showed an approach within the time to contact.
    streak: u32,
    /// The streak's first reading.
    since: Reading,
}

impl Window {
    fn push(&mut self, reading: Reading) {
        if self.n == WINDOW {
            self.readings.copy_within(1.., 0);
            self.n -= 1;
        }
        self.readings[self.n] = reading;
        self.n += 1;
    }

    fn last(&self) -> Option<&Reading> {
        self.n.checked_sub(1).map(|k| &self.readings[k])
    }

    /// The least-squares slope of the compensated range (m/s), once the window is full.
    fn slope(&self) -> Option<f64> {
        let q = self.last()?.p;
        if self.n < WINDOW {
            return None;
        }
        let c = self.readings.map(|x| x.compensated(q));
        let mt = self.readings.iter().map(|x| x.t).sum::<f64>() / WINDOW as f64;
        let mc = c.iter().sum::<f64>() / WINDOW as f64;
        let (mut stc, mut stt) = (0.0, 0.0);
        for (x, c) in self.readings.iter().zip(c) {
            stc += (x.t - mt) * (c - mc);
            stt += (x.t - mt) * (x.t - mt);
        }
        (stt > 0.0).then(|| stc / stt)
    }
}

/// The detector: odometry history and one window per sensor.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct Approach {
    p: ApproachParams,
    poses: VecDeque<(u64, Pose2)>,
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
        self.poses.push_back((t, w));
    }

    /// The robot's pose at `t`: interpolated between odometry poses, extrapolated from the last
    /// two past the newest.
    fn pose_at(&self, t: u64) -> Option<Pose2> {
        let n = self.poses.len();
        let first = self.poses.front()?;
        if n == 1 || t <= first.0 {
            return Some(first.1);
        }
        let k = self.poses.iter().position(|&(s, _)| s >= t).unwrap_or(n - 1).max(1);
        let ((t0, a), (t1, b)) = (self.poses[k - 1], self.poses[k]);
        let f = (t as f64 - t0 as f64) / (t1 as f64 - t0 as f64);
        Some(Pose2 {
            x_m: a.x_m + f * (b.x_m - a.x_m),
            y_m: a.y_m + f * (b.y_m - a.y_m),
            heading_rad: a.heading_rad + f * (b.heading_rad - a.heading_rad),
        })
    }

    /// The robot's velocity (world frame, m/s) from its two newest poses.
    fn velocity(&self) -> [f64; 2] {
        let n = self.poses.len();
        if n < 2 {
            return [0.0; 2];
        }
        let ((t0, a), (t1, b)) = (self.poses[n - 2], self.poses[n - 1]);
        let dt = (t1 - t0) as f64 * 1e-9;
        [(b.x_m - a.x_m) / dt, (b.y_m - a.y_m) / dt]
    }

    /// Folds in a ring's new readings: each sensor's streak counts its consecutive readings
    /// that showed something coming at the robot at least the least approach speed, within the
    /// time to contact.
    pub fn on_ring(&mut self, ring: &SonarRing) {
        let v = self.velocity();
        for i in 0..SONAR_SENSORS {
            let (r, stamp) = (ring.range_m[i], ring.reading_stamp_ns[i]);
            let valid = ring.valid_mask & (1 << i) != 0 && r.is_finite();
            let Some(Pose2 { x_m: x, y_m: y, heading_rad: th }) = self.pose_at(stamp) else { continue };
            let w = &mut self.windows[i];
            if !valid {
                *w = Window::default();
                continue;
            }
            if stamp <= w.last_stamp {
                continue; // no new reading of this sensor
            }
            w.last_stamp = stamp;
            let dir = th + bearing_rad(i);
            let reading = Reading {
                t: stamp as f64 * 1e-9,
                r: f64::from(r),
                p: [x, y],
                u: [dir.cos(), dir.sin()],
                heading: th,
            };
            let jumped = w.last().is_some_and(|l| (reading.compensated(l.p) - l.r).abs() > MAX_STEP_M);
            let turned = w.n > 0 && (th - w.readings[0].heading).abs() > self.p.max_turn_rad;
            if turned || jumped {
                *w = Window { last_stamp: stamp, ..Window::default() };
            }
            let u = reading.u;
            w.push(reading);
            let approach = w.slope().map_or(0.0, |s| -s);
            let closing = approach + v[0] * u[0] + v[1] * u[1];
            let coming = approach >= self.p.min_approach_mps
                && closing > 0.0
                && f64::from(r) / closing <= self.p.ttc_s;
            let kept_coming = |s: &Reading| {
                reading.compensated(s.p) - s.r
                    <= -self.p.min_approach_mps.max(approach / 2.0) * (reading.t - s.t)
            };
            (w.streak, w.since) = match (coming, w.streak) {
                (false, _) => (0, reading),
                (true, 0) => (1, reading),
                (true, n) if kept_coming(&w.since) => (n + 1, w.since),
                // Coming by the fit, not by the readings since the streak began: a new streak.
                (true, _) => (1, reading),
            };
        }
    }

    /// Consecutive readings of sensor `i` that showed an approach.
    pub fn streak(&self, i: usize) -> u32 {
        self.windows[i].streak
    }
}
