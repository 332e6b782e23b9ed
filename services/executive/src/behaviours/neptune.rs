//! CMU's stop-go-stop visual navigation (003, Neptune): at each stop the robot stands still and
//! looks (a stereo odometry request, the motion since the last look predicted by the encoders as
//! the paper's planner predicted it); the position model moves by the motion stereo solved (by
//! the prediction when it solved none: a stop counted unsolved, the encoders' run scaled by what
//! the solved steps measured of them, `odo_scale.rs`), the obstacle points join the
//! map, a path is planned round them to the goal, and the robot goes a step along it: turns
//! towards the step's end, drives to it by the encoders, and stops to look again. A step the
//! sonar's panic-stop holds back ends there, the ring's near echoes join the map (stereo ranges
//! nothing nearer than 003's near limit, so a corner first met close is the sonar's), and the
//! robot backs off as far as the way behind allows before it looks (`neptune_held.rs`).

use harvey_geometry::wrap;
use harvey_msgs::{
    BehaviourState, Header, MotionCommand, Pose2, SonarRing, VisionAlgorithm, VisionRequest, VisionResult,
    VisionStatus,
};

use super::drive;
use super::grid_plan::{Grid, along, kept_or_fresh};
use super::odo_scale::OdoScale;
use crate::mission::NeptuneGoal;

/// The odometry request's id: the vision workers keep one odometry per id.
pub const REQUEST_ID: u32 = 3003;

/// A turn or a drive taking `s` seconds unhindered is given up after twice that and 3 s more
/// (the sonar's reflexes hold the robot back while something is near).
fn allowance(s: f64) -> u64 {
    ((2.0 * s + 3.0) * 1e9) as u64
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Standing still since then (the first tick sets it), before a look.
    Settling {
        since_ns: Option<u64>,
    },
    /// Waiting for the answer until then; asked again after it (a worker restarted meanwhile
    /// has lost the request).
    Looking {
        until_ns: u64,
    },
    /// Towards the step's end, in the encoders' frame; given up (to look again) at the deadline
    /// (0: not set yet), when a reflex has held the robot back. A turn-only step (`then_move`
    /// false), one too wide for two stops' views to share enough, ends in a look.
    Turning {
        to: [f64; 2],
        deadline_ns: u64,
        then_move: bool,
    },
    Moving {
        to: [f64; 2],
        deadline_ns: u64,
    },
    /// Backing straight from `from` (the encoders' frame) after the panic-stop held a step back,
    /// until `back_m` is behind it, the way behind closes, or the deadline.
    Backing {
        from: [f64; 2],
        back_m: f64,
        deadline_ns: u64,
    },
}

/// The navigation's state.
#[derive(Debug, Clone)]
pub struct Neptune {
    g: NeptuneGoal,
    phase: Phase,
    /// The position model (world frame) at the last look, from stereo alone.
    model: Pose2,
    /// The encoders' pose at the last look, and now.
    looked_at: Option<Pose2>,
    at: Pose2,
    ring: Option<SonarRing>,
    /// Obstacle points seen (world frame, m), each with where it was seen from.
    obstacles: Vec<([f64; 2], [f64; 2])>,
    sonar: Sonar,
    /// The ring's sensors with something near on successive readings.
    near: held::NearStreaks,
    /// Steps the panic-stop held back.
    pub holds: u32,
    /// The path the last step was taken along (world frame, the goal last).
    route: Vec<[f64; 2]>,
    /// The encoders' distance scale the solved steps measure.
    scale: OdoScale,
    /// Looks answered, and those whose motion came from the prediction.
    pub stops: u32,
    pub unsolved: u32,
    next_id: u32,
    seq: u64,
    pub done: Option<bool>,
}

impl Neptune {
    pub fn new(g: NeptuneGoal, start: Pose2, sonar: Sonar) -> Self {
        Self {
            g,
            sonar,
            near: held::NearStreaks::default(),
            holds: 0,
            phase: Phase::Settling { since_ns: None },
            model: start,
            looked_at: None,
            at: start,
            ring: None,
            obstacles: Vec::new(),
            route: Vec::new(),
            scale: OdoScale::default(),
            stops: 0,
            unsolved: 0,
            next_id: 1,
            seq: 0,
            done: None,
        }
    }

    pub fn on_sonar(&mut self, r: &SonarRing) {
        self.ring = Some(*r);
        self.near.update(r, self.sonar.ring_m, self.g.clearance_m);
    }

    /// The position model carried on by the encoders since the last look.
    pub fn believed(&self) -> Pose2 {
        match self.looked_at {
            Some(l) => self.model.compose(&self.scale.apply(l.relative(&self.at))),
            None => self.model,
        }
    }

    pub fn goal_pose(&self) -> Pose2 {
        Pose2 { x_m: self.g.goal_m[0], y_m: self.g.goal_m[1], heading_rad: 0.0 }
    }

    /// The answer to the look: the model moved, the obstacles mapped, the next step planned.
    pub fn on_vision(&mut self, r: &VisionResult) {
        if r.request_id != REQUEST_ID || !matches!(self.phase, Phase::Looking { .. }) {
            return;
        }
        let encoders = self.looked_at.map(|l| l.relative(&self.at));
        let items = &r.items[..(r.count as usize).min(r.items.len())];
        let status = VisionStatus::from_raw(r.status);
        // Solved: the motion; else (none solved, or a worker that started afresh) the prediction.
        let solved = status == Some(VisionStatus::Found) && items.len() >= 2 && items[1].values[2] > 0.0;
        let motion = match (solved, encoders) {
            (true, _) => {
                let [dx, dy, dh, ..] = items[0].values.map(f64::from);
                let m = Pose2 { x_m: dx, y_m: dy, heading_rad: dh };
                if let Some(e) = encoders {
                    self.scale.learn(e, m);
                }
                Some(m)
            }
            (false, Some(e)) => {
                self.unsolved += 1;
                tracing::warn!(
                    stop = self.stops,
                    ?status,
                    "no motion from stereo: the stop is dead reckoned"
                );
                Some(self.scale.apply(e))
            }
            (false, None) => None,
        };
        if let Some(m) = motion {
            self.model = self.model.compose(&m);
        }
        self.stops += 1;
        self.looked_at = Some(self.at);
        if status == Some(VisionStatus::Found) || status == Some(VisionStatus::NotFound) {
            let (model, from) = (self.model, [self.model.x_m, self.model.y_m]);
            let seen =
                items.iter().skip(2).map(|i| model.apply([f64::from(i.values[0]), f64::from(i.values[1])]));
            self.obstacles.extend(seen.map(|p| (p, from)));
        }
        let here = [self.model.x_m, self.model.y_m];
        if (here[0] - self.g.goal_m[0]).hypot(here[1] - self.g.goal_m[1]) <= self.g.goal_tolerance_m {
            tracing::info!(stops = self.stops, unsolved = self.unsolved, holds = self.holds, "at the goal");
            self.done = Some(true);
            return;
        }
        let Some(target) = self.plan(here) else {
            tracing::warn!(stops = self.stops, "the position model has left the room: no path to the goal");
            self.done = Some(false);
            return;
        };
        // A turn wider than the views allow is a step of its own, towards the target.
        let e = wrap((target[1] - here[1]).atan2(target[0] - here[0]) - self.model.heading_rad);
        let widest = self.g.max_step_turn_deg.to_radians();
        let (target, then_move) = if e.abs() <= widest {
            (target, true)
        } else {
            let towards = self.model.heading_rad + widest.copysign(e);
            ([here[0] + towards.cos(), here[1] + towards.sin()], false)
        };
        // The step's end in the encoders' frame, where the robot drives by them: ahead of the
        // model as far as ahead of the encoders' pose.
        let ahead = self.model.inverse().apply(target);
        self.phase = Phase::Turning { to: self.at.apply(ahead), deadline_ns: 0, then_move };
    }

    /// The end of the next step: `step_m` along the cheapest path round the obstacles (or the
    /// last stop's, while not much dearer: `kept_or_fresh`), their
    /// clearance a margin and their hard clearance the robot's reach. Stereo sees an obstacle's
    /// face, not what is behind it: each point also blocks its shadow, `shadow_m` on along the
    /// ray it was seen by (the body of a box seen from the front).
    fn plan(&mut self, here: [f64; 2]) -> Option<[f64; 2]> {
        let g = &self.g;
        let samples = (g.shadow_m / (g.cell_m / 2.0)).ceil().max(1.0) as usize;
        let mut grid = Grid::new(g.room_min_m, g.room_max_m, g.cell_m);
        for (p, from) in &self.obstacles {
            let (dx, dy) = (p[0] - from[0], p[1] - from[1]);
            let d = dx.hypot(dy).max(1e-9);
            for k in 0..=samples {
                let s = g.shadow_m * k as f64 / samples as f64;
                let at = [p[0] + dx / d * s, p[1] + dy / d * s];
                grid.block(at, g.clearance_m, 1);
                grid.block(at, g.hard_clearance_m, 2);
            }
        }
        let fresh = grid.path(here, g.goal_m)?;
        self.route = kept_or_fresh(&grid, here, std::mem::take(&mut self.route), fresh);
        Some(along(here, &self.route, g.step_m))
    }

    /// One odometry tick: the look to send, the velocity command and the state to publish.
    pub fn on_odometry(
        &mut self,
        at: Pose2,
        now: u64,
    ) -> (Option<VisionRequest>, MotionCommand, BehaviourState) {
        self.at = at;
        let g = self.g;
        let max_turn = g.max_turn_degps.to_radians();
        let mut look = None;
        let vw = match self.phase {
            Phase::Settling { since_ns: None } => {
                self.phase = Phase::Settling { since_ns: Some(now) };
                (0.0, 0.0)
            }
            Phase::Settling { since_ns: Some(t) } => {
                if now >= t + (g.settle_s * 1e9) as u64 && self.done.is_none() {
                    look = Some(self.look(now));
                    self.phase = Phase::Looking { until_ns: now + (g.look_timeout_s * 1e9) as u64 };
                }
                (0.0, 0.0)
            }
            Phase::Looking { until_ns } => {
                if now >= until_ns {
                    tracing::warn!(stop = self.stops, "no answer to the look: asking again");
                    look = Some(self.look(now));
                    self.phase = Phase::Looking { until_ns: now + (g.look_timeout_s * 1e9) as u64 };
                }
                (0.0, 0.0)
            }
            Phase::Turning { to, deadline_ns, then_move } => {
                let e = wrap((to[1] - at.y_m).atan2(to[0] - at.x_m) - at.heading_rad);
                let deadline_ns = match deadline_ns {
                    0 => now + allowance(e.abs() / max_turn),
                    d => d,
                };
                if e.abs() <= g.aligned_deg.to_radians() {
                    self.phase = match then_move {
                        true => Phase::Moving { to, deadline_ns: 0 },
                        false => Phase::Settling { since_ns: Some(now) },
                    };
                    (0.0, 0.0)
                } else if now >= deadline_ns {
                    self.phase = Phase::Settling { since_ns: Some(now) };
                    (0.0, 0.0)
                } else {
                    self.phase = Phase::Turning { to, deadline_ns, then_move };
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
                let held = self.ring.is_some_and(|r| r.panic_stop != 0);
                if held {
                    self.map_echoes();
                    let back_m = self.room_behind();
                    let deadline_ns = now + allowance(back_m / g.speed_mps);
                    // A back-off no longer than a step's arrival tolerance is none (and ends one).
                    self.phase = match back_m > g.arrive_m {
                        true => Phase::Backing { from: [at.x_m, at.y_m], back_m, deadline_ns },
                        false => Phase::Settling { since_ns: Some(now) },
                    };
                    (0.0, 0.0)
                } else if dx.hypot(dy) <= g.arrive_m || ahead <= 0.0 || now >= deadline_ns {
                    self.phase = Phase::Settling { since_ns: Some(now) };
                    (0.0, 0.0)
                } else {
                    self.phase = Phase::Moving { to, deadline_ns };
                    let e = wrap(dy.atan2(dx) - at.heading_rad);
                    (g.speed_mps.min(ahead), (g.turn_gain * e).clamp(-max_turn, max_turn))
                }
            }
            Phase::Backing { from, back_m, deadline_ns } => {
                let backed = (at.x_m - from[0]).hypot(at.y_m - from[1]);
                if backed >= back_m || now >= deadline_ns || self.room_behind() <= g.arrive_m {
                    self.phase = Phase::Settling { since_ns: Some(now) };
                    (0.0, 0.0)
                } else {
                    (-g.speed_mps, 0.0)
                }
            }
        };
        let vw = drive::held(self.ring.as_ref(), vw);
        let id = self.next_id;
        self.next_id += 1;
        self.seq += 1;
        let phase = match self.phase {
            Phase::Settling { .. } => 0,
            Phase::Looking { .. } => 1,
            Phase::Turning { .. } => 2,
            Phase::Moving { .. } => 3,
            Phase::Backing { .. } => 4,
        };
        let state = BehaviourState {
            header: Header::new(self.seq, now),
            at: self.believed(),
            fsa_state: phase,
            transitions: self.stops,
            last_trigger: 0,
            achieved: self.stops - self.unsolved.min(self.stops),
            vectors_mps: [0.0; 12],
            linear_mps: vw.0,
            angular_radps: vw.1,
        };
        (look, drive::command(id, now, vw), state)
    }

    /// The look: the odometry request with the encoders' motion since the last look as the
    /// prediction (the first look starts the odometry).
    fn look(&self, now: u64) -> VisionRequest {
        let expected = self.looked_at.map_or(Pose2::default(), |l| l.relative(&self.at));
        let start = if self.looked_at.is_none() { 1.0 } else { 0.0 };
        let mut params = [0.0f32; 8];
        params[..2].copy_from_slice(&[start, if self.g.lucas { 1.0 } else { 0.0 }]);
        VisionRequest {
            header: Header::new(self.seq + 1, now),
            request_id: REQUEST_ID,
            algorithm: VisionAlgorithm::StereoOdometry as u32,
            standing: 0,
            expected,
            params,
            ..VisionRequest::default()
        }
    }
}

#[path = "neptune_held.rs"]
mod held;
pub use held::Sonar;

#[cfg(test)]
#[path = "neptune_tests.rs"]
mod tests;
