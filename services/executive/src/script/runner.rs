//! The executive's script runner: each TURN/MOVE primitive commanded and checked against
//! odometry, incremental legs with their looks (000 §5.5), getting back to an interrupted step
//! after a reflex, plan-and-monitor's steps appended as they are needed, and the behaviours'
//! commands passed through.

use harvey_msgs::{
    CommandKind, Header, MissionState, MotionCommand, Odometry, Pose2, ServoCorrection, VisionRequest,
    VisionResult, VisionStatus,
};

use crate::leg::{Leg, LegStep};
use crate::mission::Step;
use crate::{Executive, Output, Phase, goal_of, monitor, recover, refining};

impl Executive {
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
    fn begin(&mut self, step: usize, at: Pose2, now: u64) -> Vec<Output> {
        self.step_goal = goal_of(at, std::slice::from_ref(&self.mission.steps[step]));
        let s: &Step = &self.mission.steps[step];
        if s.refine_pose {
            return self.begin_refine(step, now);
        }
        match (s.move_m, s.turn_deg, s.increment_m) {
            (Some(d), _, Some(inc)) => {
                let servo = self.servo.get(step).copied().flatten();
                let mut leg = Leg::new(at, d, inc, servo);
                let first = leg.start();
                self.leg = Some(leg);
                self.apply(step, first, at, now)
            }
            (Some(d), _, None) => vec![self.send(step, CommandKind::Move, d, 0.0, now)],
            (_, a, _) => vec![self.send(step, CommandKind::Turn, 0.0, a.unwrap_or(0.0).to_radians(), now)],
        }
    }

    /// Carries out what the leg of step `step` wants next.
    fn apply(&mut self, step: usize, next: LegStep, at: Pose2, now: u64) -> Vec<Output> {
        match next {
            LegStep::Move(d) => vec![self.send(step, CommandKind::Move, d, 0.0, now)],
            LegStep::Turn(a) => {
                if let Some(l) = &self.leg {
                    let h = l.corrections.last().map_or(0.0, |c| c.0);
                    tracing::info!(
                        heading_error_deg = h.to_degrees(),
                        turn_deg = a.to_degrees(),
                        offset_in = l.offset_m / 0.0254,
                        shortfall_m = l.shortfall_m,
                        "servo correction"
                    );
                }
                vec![self.send(step, CommandKind::Turn, 0.0, a, now)]
            }
            LegStep::Look(expected) => {
                let (Some(s), Some(sv)) = (self.leg.as_ref().and_then(|l| l.servo), self.mission.servo)
                else {
                    return Vec::new();
                };
                let request = self.next_request;
                self.next_request += 1;
                self.phase = Phase::Looking { step, request };
                vec![Output::Look(VisionRequest::correlate(
                    request,
                    now,
                    s.landmark_index,
                    expected,
                    s.offset,
                    sv.template_px,
                    sv.min_score,
                ))]
            }
            LegStep::Done => {
                if let Some(l) = self.leg.take() {
                    self.legs.push(l);
                }
                self.step_done(step, at, now)
            }
        }
    }

    /// Step `step` is over: the next one, what the plan wants next, or success.
    pub(crate) fn step_done(&mut self, step: usize, at: Pose2, now: u64) -> Vec<Output> {
        if step + 1 < self.mission.steps.len() {
            self.begin(step + 1, at, now)
        } else if self.plan.is_some() {
            self.plan_next(at, now)
        } else {
            self.phase = Phase::Done(MissionState::Succeeded);
            Vec::new()
        }
    }

    /// Plan-and-monitor's next steps, appended to the script and begun.
    fn plan_next(&mut self, at: Pose2, now: u64) -> Vec<Output> {
        let Some(plan) = self.plan.as_mut() else { return Vec::new() };
        let next = plan.next(at, self.fixes);
        self.plan_seq += 1;
        let mut out = vec![Output::Plan(plan.sketch_msg(self.plan_seq, now))];
        match next {
            Ok(monitor::Next::Steps(steps)) => {
                let first = self.mission.steps.len();
                self.mission.steps.extend(steps);
                out.extend(self.begin(first, at, now));
            }
            Ok(monitor::Next::Arrived) => self.phase = Phase::Done(MissionState::Succeeded),
            Err(e) => {
                tracing::error!(error = %e, "plan-and-monitor failed");
                self.phase = Phase::Done(MissionState::Failed);
            }
        }
        out
    }

    /// The next primitive of the way back to the interrupted step's goal, or the next step.
    fn resume(&mut self, step: usize, at: Pose2, now: u64) -> Vec<Output> {
        match self.recovery.pop() {
            Some((kind, v)) if kind == CommandKind::Move => vec![self.send(step, kind, v, 0.0, now)],
            Some((kind, v)) => vec![self.send(step, kind, 0.0, v, now)],
            None => self.step_done(step, at, now),
        }
    }

    /// A vision result: the answer to the leg's look, if it is the one awaited.
    pub fn on_vision(&mut self, r: &VisionResult) -> Vec<Output> {
        if let Some(b) = self.behaviour.as_mut() {
            b.on_vision(r);
            return Vec::new();
        }
        if matches!(self.phase, Phase::Refining { .. }) {
            return self.on_refine_result(r);
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
        out.extend(self.apply(step, next, at, now));
        out
    }

    /// One odometry message: advance the script; returns commands and the status to publish.
    pub fn on_odometry(&mut self, o: &Odometry) -> Vec<Output> {
        let now = o.header.stamp_ns;
        self.odometry = o.world_from_robot;
        self.estimated = self.believed();
        let at = self.estimated;
        let mut out = Vec::new();
        if let Some(b) = self.behaviour.as_mut() {
            if matches!(self.phase, Phase::Waiting) {
                self.start_ns = now;
                self.phase = Phase::Executing { step: 0, id: 0 };
            }
            if !matches!(self.phase, Phase::Done(_)) {
                let (look, command, state) = b.on_odometry(at, now);
                (self.estimated, self.goal) = (b.believed(at), b.goal_pose());
                out.extend(look.map(Output::Look));
                out.push(Output::Command(command));
                out.push(Output::Behaviour(state));
                if let Some(well) = b.done() {
                    self.phase =
                        Phase::Done(if well { MissionState::Succeeded } else { MissionState::Failed });
                }
            }
        }
        match self.phase {
            _ if self.behaviour.is_some() => {}
            Phase::Waiting => {
                self.start_ns = now;
                match &self.plan {
                    Some(plan) => {
                        self.goal = plan.goal_pose();
                        out = self.plan_next(at, now);
                    }
                    None => {
                        self.goal = goal_of(at, &self.mission.steps);
                        out = self.begin(0, at, now);
                    }
                }
            }
            Phase::Executing { step, .. } | Phase::Looking { step, .. }
                if recover::is_reflex(o.command.command_id)
                    && o.command.command_id != self.handled_reflex =>
            {
                tracing::warn!(step, "a reflex took the vehicle; the step resumes once it is over");
                self.preemptions += 1;
                self.handled_reflex = o.command.command_id;
                self.leg = None;
                self.recovery.clear();
                self.phase = Phase::Preempted { step, since_ns: now };
            }
            Phase::Preempted { step, since_ns } => {
                let fresh =
                    recover::is_reflex(o.command.command_id) && o.command.command_id != self.handled_reflex;
                if fresh {
                    self.handled_reflex = o.command.command_id;
                }
                if fresh || o.moving != 0 || o.command_accepted == 0 {
                    self.phase = Phase::Preempted { step, since_ns: now };
                } else if now.saturating_sub(since_ns) >= recover::QUIET_NS {
                    self.recovery = recover::back_to(at, self.step_goal);
                    self.recovery.reverse();
                    out = self.resume(step, at, now);
                }
            }
            Phase::Executing { step, id } => {
                let finished = o.command.command_id == id && o.command_accepted == 1 && o.moving == 0;
                if finished && !self.recovery.is_empty() {
                    out = self.resume(step, at, now);
                } else if finished {
                    out = match self.leg.as_mut() {
                        Some(leg) => {
                            let next = leg.on_done();
                            self.apply(step, next, at, now)
                        }
                        None => self.step_done(step, at, now),
                    };
                }
            }
            Phase::Refining { step, since_ns, .. } if now.saturating_sub(since_ns) > refining::WAIT_NS => {
                out = self.finish_refine(step, now);
            }
            Phase::Looking { .. } | Phase::Refining { .. } | Phase::Done(_) => {}
        }
        let running = !matches!(self.phase, Phase::Done(_));
        if running && now.saturating_sub(self.start_ns) as f64 > self.mission.timeout_s * 1e9 {
            let enough = self.behaviour.as_ref().is_some_and(|b| b.enough_at_timeout());
            self.phase = Phase::Done(if enough { MissionState::Succeeded } else { MissionState::Failed });
            out.push(Output::Command(MotionCommand {
                header: Header::new(u64::from(self.next_id), now),
                kind: CommandKind::Stop as u32,
                command_id: self.next_id,
                ..Default::default()
            }));
        }
        out.push(Output::Status(self.status(now)));
        out
    }
}
