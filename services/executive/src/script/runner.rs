//! The script runner's steps: each TURN/MOVE primitive commanded and checked against odometry,
//! incremental legs with their looks (000 §5.5), getting back to an interrupted step after a
//! reflex, and the [`Sequel`]'s steps appended once the script's own are done.

use harvey_msgs::{
    CommandKind, Header, MotionCommand, Odometry, Pose2, ServoCorrection, VisionRequest, VisionResult,
    VisionStatus,
};

use super::leg::{Leg, LegStep};
use super::{Fixes, More, Phase, Script, Sequel, recover};
use crate::Output;

impl Script {
    fn send(&mut self, step: usize, kind: CommandKind, distance_m: f64, angle_rad: f64, now: u64) -> Output {
        let id = self.next_id;
        self.next_id += 1;
        self.phase = Phase::Executing { step, id };
        Output::Command(MotionCommand {
            header: Header::new(u64::from(id), now),
            kind: kind as u32,
            distance_m,
            angle_rad,
            command_id: id,
            ..Default::default()
        })
    }

    /// Starts step `step` from the pose `at`.
    pub(super) fn begin(&mut self, step: usize, at: Pose2, now: u64, sequel: &mut dyn Sequel) -> Vec<Output> {
        self.step_goal = super::goal_of(at, std::slice::from_ref(&self.steps[step]));
        let s = &self.steps[step];
        if s.refine_pose {
            return self.begin_refine(step, now, sequel);
        }
        match (s.move_m, s.turn_deg, s.increment_m) {
            (Some(d), _, Some(inc)) => {
                let servo = self.servo.get(step).copied().flatten();
                let mut leg = Leg::new(at, d, inc, servo);
                let first = leg.start();
                self.leg = Some(leg);
                self.apply(step, first, at, now, sequel)
            }
            (Some(d), _, None) => vec![self.send(step, CommandKind::Move, d, 0.0, now)],
            (_, a, _) => vec![self.send(step, CommandKind::Turn, 0.0, a.unwrap_or(0.0).to_radians(), now)],
        }
    }

    /// Carries out what the leg of step `step` wants next.
    fn apply(
        &mut self,
        step: usize,
        next: LegStep,
        at: Pose2,
        now: u64,
        sequel: &mut dyn Sequel,
    ) -> Vec<Output> {
        self.leg_anchor = (next != LegStep::Done).then_some((at, next));
        match next {
            LegStep::Move(d) => vec![self.send(step, CommandKind::Move, d, 0.0, now)],
            LegStep::Turn(a) => {
                if let Some(l) = &self.leg {
                    let h = l.corrections.last().map_or(0.0, |c| c.0);
                    tracing::info!(
                        heading_error_deg = h.to_degrees(),
                        turn_deg = a.to_degrees(),
                        offset_in = l.offset_m / harvey_geometry::INCH,
                        shortfall_m = l.shortfall_m,
                        "servo correction"
                    );
                }
                vec![self.send(step, CommandKind::Turn, 0.0, a, now)]
            }
            LegStep::Look(expected) => {
                let (Some(l), Some(sv)) = (self.leg.as_ref(), self.servo_table) else {
                    return Vec::new();
                };
                let Some(s) = l.servo else { return Vec::new() };
                // Tracked only where a sighting the leg would accept can be; the first look, with
                // the mount not yet measured, also where the mount's error can put it.
                let window = if l.discovering() {
                    super::window::first_look_window(&s, expected, l.mount_rad, sv.template_px)
                } else {
                    super::window::look_window(&s, expected, l.mount_rad, l.offset_m, sv.template_px)
                };
                let request = self.next_request;
                self.next_request += 1;
                self.phase = Phase::Looking { step, request };
                let mut look = VisionRequest::correlate(
                    request,
                    now,
                    s.landmark_index,
                    expected,
                    s.offset,
                    sv.template_px,
                    sv.min_score,
                );
                if let Some(w) = window {
                    look.window_px = w;
                }
                vec![Output::Look(look)]
            }
            LegStep::Done => {
                if let Some(l) = self.leg.take() {
                    self.legs.push(l);
                }
                self.step_done(step, at, now, sequel)
            }
        }
    }

    /// Step `step` is over: the next one, or what the sequel has next.
    pub(super) fn step_done(
        &mut self,
        step: usize,
        at: Pose2,
        now: u64,
        sequel: &mut dyn Sequel,
    ) -> Vec<Output> {
        if step + 1 < self.steps.len() {
            self.begin(step + 1, at, now, sequel)
        } else {
            self.more(at, now, sequel)
        }
    }

    /// The sequel's next steps, appended to the script and begun, or the mission's end.
    fn more(&mut self, at: Pose2, now: u64, sequel: &mut dyn Sequel) -> Vec<Output> {
        let mut out = Vec::new();
        let fixes = Fixes { count: self.fixes, last_sd_m: self.fix_sd_m };
        match sequel.more(at, fixes, now, &mut out) {
            More::Steps(steps) => {
                let first = self.steps.len();
                self.steps.extend(steps);
                out.extend(self.begin(first, at, now, sequel));
            }
            More::End(state) => self.phase = Phase::Done(state),
        }
        out
    }

    /// The next primitive of the way back to the interrupted step's goal, or the next step.
    fn resume(&mut self, step: usize, at: Pose2, now: u64, sequel: &mut dyn Sequel) -> Vec<Output> {
        // The panic-stop stops only a vehicle driving forward: into what it sees too close
        // ahead, a MOVE would creep a few centimetres a try. And none watches behind: a MOVE
        // backing further than the ring shows clear (the cart that was evaded, going by) waits
        // too, until the way is clear.
        let d = match (self.recovery.last(), self.redo) {
            (Some(&(CommandKind::Move, d)), _) => d,
            (None, Some(LegStep::Move(d))) => d,
            _ => 0.0,
        };
        if (d > 0.0 && self.clearance.blocked_ahead) || -d > self.clearance.may_back_m() {
            self.phase = Phase::Preempted { step, since_ns: now };
            return Vec::new();
        }
        match self.recovery.pop() {
            Some((kind, v)) if kind == CommandKind::Move => vec![self.send(step, kind, v, 0.0, now)],
            Some((kind, v)) => vec![self.send(step, kind, 0.0, v, now)],
            None => match self.redo.take() {
                Some(next) => self.apply(step, next, at, now, sequel),
                None => self.step_done(step, at, now, sequel),
            },
        }
    }

    /// A vision result: the answer to the leg's look, if it is the one awaited, or to the
    /// refinement under way.
    pub fn on_vision(&mut self, r: &VisionResult, sequel: &mut dyn Sequel) -> Vec<Output> {
        if matches!(self.phase, Phase::Refining { .. }) {
            return self.on_refine_result(r, sequel);
        }
        let Phase::Looking { step, request } = self.phase else { return Vec::new() };
        if r.request_id != request {
            return Vec::new();
        }
        let found = (VisionStatus::from_raw(r.status) == Some(VisionStatus::Found) && r.count > 0)
            .then(|| [f64::from(r.items[0].values[0]), f64::from(r.items[0].values[1])]);
        let Some(leg) = self.leg.as_mut() else { return Vec::new() };
        let before = leg.corrections.len();
        let next = leg.on_seen(found);
        let (at, now) = (self.estimated, r.header.stamp_ns);
        let mut out = Vec::new();
        if let (Some(&(h, turn)), Some(px), Some(s)) = (leg.corrections.get(before), found, leg.servo) {
            self.servo_seq += 1;
            out.push(Output::Servo(ServoCorrection {
                header: Header::new(self.servo_seq, now),
                increment: leg.increments_done() as u32,
                landmark_index: s.landmark_index,
                found_px: px.map(|v| v as f32),
                heading_error_rad: h,
                correction_rad: turn,
                offset_m: leg.offset_m,
                shortfall_m: leg.shortfall_m,
            }));
        }
        out.extend(self.apply(step, next, at, now, sequel));
        out
    }

    /// One odometry message: advances the script; returns the commands and requests to send.
    pub fn on_odometry(&mut self, o: &Odometry, sequel: &mut dyn Sequel) -> Vec<Output> {
        let now = o.header.stamp_ns;
        self.belief.set_odometry(o.world_from_robot);
        self.estimated = self.belief.believed();
        let at = self.estimated;
        let reflex = o.command.command_id;
        let fresh_reflex = recover::is_reflex(reflex) && reflex != self.handled_reflex;
        match self.phase {
            Phase::Waiting => {
                self.goal = sequel.goal(at, &self.steps);
                if self.steps.is_empty() {
                    self.more(at, now, sequel)
                } else {
                    self.begin(0, at, now, sequel)
                }
            }
            Phase::Executing { step, .. } | Phase::Looking { step, .. } if fresh_reflex => {
                tracing::warn!(step, "a reflex took the vehicle; the step resumes once it is over");
                self.preemptions += 1;
                self.handled_reflex = reflex;
                if self.leg_anchor.is_none() {
                    self.leg = None;
                }
                self.recovery.clear();
                self.redo = None;
                self.phase = Phase::Preempted { step, since_ns: now };
                Vec::new()
            }
            Phase::Preempted { step, since_ns } => {
                if fresh_reflex {
                    self.handled_reflex = reflex;
                }
                // Quiet: no new reflex command and the vehicle still. Not whether it took the
                // newest command: odometry names the newest published, which is often a reflex's
                // stop sent beside the step the vehicle ran, and never taken.
                if fresh_reflex || o.moving != 0 {
                    self.phase = Phase::Preempted { step, since_ns: now };
                    Vec::new()
                } else if now.saturating_sub(since_ns) >= recover::QUIET_NS {
                    self.recovery = match (self.leg_anchor, self.leg.as_mut()) {
                        (Some((anchor, next)), Some(leg)) => {
                            // Back at the leg's start by odometry, the heading is not the line's
                            // as the mount's measurement needs: the mount stays as configured.
                            self.redo = Some(if leg.discovering() { leg.skip_calibration() } else { next });
                            recover::back_to(at, anchor, f64::INFINITY)
                        }
                        _ => recover::back_to(at, self.step_goal, 0.0),
                    };
                    self.recovery.reverse();
                    self.resume(step, at, now, sequel)
                } else {
                    Vec::new()
                }
            }
            Phase::Executing { step, id } => {
                let finished = o.command.command_id == id && o.command_accepted == 1 && o.moving == 0;
                if finished && (!self.recovery.is_empty() || self.redo.is_some()) {
                    self.resume(step, at, now, sequel)
                } else if finished {
                    match self.leg.as_mut() {
                        Some(leg) => {
                            let next = leg.on_done();
                            self.apply(step, next, at, now, sequel)
                        }
                        None => self.step_done(step, at, now, sequel),
                    }
                } else {
                    Vec::new()
                }
            }
            Phase::Refining { step, since_ns, .. } if now.saturating_sub(since_ns) > super::WAIT_NS => {
                self.finish_refine(step, now, sequel)
            }
            Phase::Looking { .. } | Phase::Refining { .. } | Phase::Done(_) => Vec::new(),
        }
    }
}
