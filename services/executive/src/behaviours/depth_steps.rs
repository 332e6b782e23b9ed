//! The ticks of obstacle avoidance by depth from motion between looks: standing still before a
//! look (and sending it), waiting for its answer, turning on the spot to a new run's heading,
//! and driving a run's step, each given up at a deadline.

use harvey_geometry::wrap;
use harvey_msgs::{Header, Pose2, VisionRequest};

use super::super::depth_look::{Look, request};
use super::{DepthObstacles, Phase, Run};

/// Speed per metre short of a step's end (per second): full speed until the last few
/// centimetres.
const ARRIVE_GAIN: f64 = 4.0;

/// The time allowed for a move that should take `s` seconds (ns).
fn allowance(s: f64) -> u64 {
    ((2.0 * s + 2.0) * 1e9) as u64
}

impl DepthObstacles {
    /// This tick's look to send, if any, and the velocity command `(v, w)`.
    pub(super) fn step(&mut self, at: Pose2, now: u64) -> (Option<VisionRequest>, (f64, f64)) {
        let g = &self.g;
        let max_turn = g.max_turn_degps.to_radians();
        let mut look = None;
        let vw = match self.phase {
            _ if self.done.is_some() => (0.0, 0.0),
            Phase::Settling { since_ns: None } => {
                self.phase = Phase::Settling { since_ns: Some(now) };
                (0.0, 0.0)
            }
            Phase::Settling { since_ns: Some(t) } => {
                if now >= t + (g.settle_s * 1e9) as u64 {
                    // A step the robot barely made (a reflex held it) moves the points too
                    // little to measure: a new run starts here.
                    let last = self.run.asked.map_or(0.0, |a| a.travelled_m);
                    if self.run.looks > 0 && self.travelled() - last < g.step_m / 2.0 {
                        self.run.number += 1;
                        self.run.looks = 0;
                    }
                    if self.run.looks == 0 {
                        self.run = Run::new(at, self.run.number, self.believed());
                    }
                    let turned = wrap(at.heading_rad - self.run.start.heading_rad);
                    let travelled = if self.run.looks == 0 { 0.0 } else { self.travelled() };
                    let how = Look { number: self.run.number, travelled_m: travelled, turned_rad: turned };
                    self.run.asked = Some(how);
                    look = Some(request(&self.g, self.window_px, how, Header::new(self.seq + 1, now)));
                    self.phase = Phase::Looking { until_ns: now + (g.look_timeout_s * 1e9) as u64 };
                }
                (0.0, 0.0)
            }
            Phase::Looking { until_ns } => {
                if now >= until_ns {
                    tracing::warn!(run = self.run.number, "no answer to the look: a new run");
                    self.run = Run::new(at, self.run.number + 1, self.believed());
                    self.phase = Phase::Settling { since_ns: Some(now) };
                }
                (0.0, 0.0)
            }
            Phase::Turning { to, deadline_ns } => {
                let e = wrap(to - at.heading_rad);
                let deadline_ns = match deadline_ns {
                    0 => now + allowance(e.abs() / max_turn),
                    d => d,
                };
                if e.abs() <= g.aligned_deg.to_radians() || now >= deadline_ns {
                    self.phase = Phase::Settling { since_ns: Some(now) };
                    (0.0, 0.0)
                } else {
                    self.phase = Phase::Turning { to, deadline_ns };
                    (0.0, (g.turn_gain * e).clamp(-max_turn, max_turn))
                }
            }
            Phase::Moving { to, deadline_ns } => {
                let (dx, dy) = (to[0] - at.x_m, to[1] - at.y_m);
                let (s, c) = at.heading_rad.sin_cos();
                let ahead = c * dx + s * dy;
                let deadline_ns = match deadline_ns {
                    0 => now + allowance(dx.hypot(dy) / g.speed_mps),
                    d => d,
                };
                if ahead <= 0.005 || now >= deadline_ns {
                    self.phase = Phase::Settling { since_ns: Some(now) };
                    (0.0, 0.0)
                } else {
                    self.phase = Phase::Moving { to, deadline_ns };
                    // Steer for the step's end, which lies on the run's line (its heading held).
                    let e = wrap(dy.atan2(dx) - at.heading_rad);
                    (g.speed_mps.min(ARRIVE_GAIN * ahead), (g.turn_gain * e).clamp(-max_turn, max_turn))
                }
            }
        };
        (look, vw)
    }
}
