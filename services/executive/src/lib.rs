//! The executive's logic: runs a mission's TURN/MOVE script, one primitive at a time, checking
//! each against odometry, and reports progress. A move may be driven in increments with
//! action-level servoing on a landmark after each (`leg.rs`, 000 §5.5). Plan-and-monitor and FSA
//! sequencing grow from here.

pub mod behaviour;
pub mod docking;
pub mod drive;
pub mod fsa;
pub mod goals;
pub mod leg;
pub mod mission;
pub mod monitor;
pub mod plan;
pub mod pole_hunt;
pub mod pose;
pub mod recover;
pub mod refining;
pub mod schemas;
pub mod sequenced;
pub mod servo;

use harvey_msgs::{BehaviourState, PlanSketch, PoseFix, SonarRing};
use harvey_msgs::{
    CommandKind, Header, MissionState, MissionStatus, MotionCommand, Odometry, Pose2, ServoCorrection,
    ServoLevel, VisionRequest, VisionResult, VisionStatus,
};
use leg::{Leg, LegStep, ServoSetup};
use mission::{Mission, Step};

/// What the executive wants sent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Output {
    Command(MotionCommand),
    Status(MissionStatus),
    Look(VisionRequest),
    Servo(ServoCorrection),
    Pose(PoseFix),
    Plan(PlanSketch),
    Behaviour(BehaviourState),
}

/// The executive's vision request ids start here (the vision workers' own standing requests
/// use small ids).
const REQUEST_BASE: u32 = 100;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// No odometry yet: the vehicle's state is unknown.
    Waiting,
    /// Step `i` (or an increment or correction of it) was commanded with id `id`.
    Executing {
        step: usize,
        id: u32,
    },
    /// Step `i` waits for the answer to vision request `request`.
    Looking {
        step: usize,
        request: u32,
    },
    /// Step `i` waits for the vision results of requests `first ..`, `received` so far.
    Refining {
        step: usize,
        first: u32,
        received: u32,
        since_ns: u64,
    },
    /// A sonar reflex took the vehicle during step `i`; it last moved at `since_ns`.
    Preempted {
        step: usize,
        since_ns: u64,
    },
    Done(MissionState),
}

/// The executive's state.
#[derive(Debug)]
pub struct Executive {
    mission: Mission,
    /// Per step, what servoing it needs (resolved from the world by the caller).
    servo: Vec<Option<ServoSetup>>,
    /// The incremental leg under way.
    pub leg: Option<Leg>,
    /// Every finished leg, for the summary.
    pub legs: Vec<Leg>,
    next_request: u32,
    /// Where the current step should leave the robot (for getting back to it after a reflex).
    step_goal: Pose2,
    /// Primitives still to run to get back to `step_goal`, next last.
    recovery: Vec<(CommandKind, f64)>,
    servo_seq: u64,
    /// Plan-level servoing: what it needs, what the current look found, the latest odometry,
    /// and the belief `(odometry then, refined pose then)` since the last refinement.
    refine: Option<refining::RefineSetup>,
    asked: Vec<usize>,
    looks: Vec<Option<[f64; 2]>>,
    /// Pose fixes made so far.
    pub fixes: u32,
    /// Plan-and-monitor, when the mission is a `ptrans` goal: it appends the steps.
    pub plan: Option<monitor::Monitor>,
    plan_seq: u64,
    /// An acceptor-sequenced behaviour (docking, the pole hunt), when the mission is one.
    pub behaviour: Option<behaviour::Behaviour>,
    odometry: Pose2,
    belief: Option<(Pose2, Pose2)>,
    /// Times a reflex interrupted the mission.
    pub preemptions: u32,
    /// The latest reflex command already dealt with (the vehicle reports it until ours is taken).
    handled_reflex: u32,
    phase: Phase,
    start_ns: u64,
    goal: Pose2,
    estimated: Pose2,
    next_id: u32,
    seq: u64,
    /// Whether the UMS's last map said lost.
    lost: bool,
    pub sonar_rings_seen: u64,
    pub detections_seen: u64,
    pub maps_seen: u64,
}

/// Where a script ends when executed exactly from `start`.
pub fn goal_of(start: Pose2, steps: &[Step]) -> Pose2 {
    steps.iter().fold(start, |p, s| match (s.move_m, s.turn_deg) {
        (Some(d), _) => {
            Pose2 { x_m: p.x_m + d * p.heading_rad.cos(), y_m: p.y_m + d * p.heading_rad.sin(), ..p }
        }
        (_, Some(a)) => Pose2 { heading_rad: p.heading_rad + a.to_radians(), ..p },
        _ => p,
    })
}

impl Executive {
    /// `servo[i]` says how step `i` servos (it must say so for every `servo_landmark` step).
    /// With plan-level servoing: what `refine_pose` steps need.
    pub fn with_refine(mut self, setup: refining::RefineSetup) -> Self {
        self.refine = Some(setup);
        self
    }

    /// With an acceptor-sequenced behaviour driving the robot.
    pub fn with_behaviour(mut self, b: behaviour::Behaviour) -> Self {
        self.behaviour = Some(b);
        self
    }

    /// An uncertainty map from the UMS: plan-and-monitor relocates when it comes to say lost.
    pub fn on_map(&mut self, m: &harvey_msgs::UncertaintyMap) {
        self.maps_seen += 1;
        let became_lost = m.lost != 0 && !self.lost;
        self.lost = m.lost != 0;
        if let Some(plan) = self.plan.as_mut().filter(|_| became_lost) {
            plan.lost();
        }
    }

    /// A sonar ring (the behaviours' obstacles and ranges).
    pub fn on_sonar(&mut self, r: &SonarRing) {
        self.sonar_rings_seen += 1;
        if let Some(b) = self.behaviour.as_mut() {
            b.on_sonar(r);
        }
    }

    /// With plan-and-monitor developing the mission's `ptrans` goal.
    pub fn with_plan(mut self, monitor: monitor::Monitor) -> Self {
        self.plan = Some(monitor);
        self
    }

    pub fn new(mission: Mission, servo: Vec<Option<ServoSetup>>) -> Self {
        Self {
            mission,
            servo,
            leg: None,
            legs: Vec::new(),
            next_request: REQUEST_BASE,
            step_goal: Pose2::default(),
            recovery: Vec::new(),
            servo_seq: 0,
            refine: None,
            asked: Vec::new(),
            looks: Vec::new(),
            fixes: 0,
            plan: None,
            plan_seq: 0,
            behaviour: None,
            odometry: Pose2::default(),
            belief: None,
            preemptions: 0,
            handled_reflex: 0,
            phase: Phase::Waiting,
            start_ns: 0,
            goal: Pose2::default(),
            estimated: Pose2::default(),
            next_id: 1,
            seq: 0,
            lost: false,
            sonar_rings_seen: 0,
            detections_seen: 0,
            maps_seen: 0,
        }
    }

    pub fn state(&self) -> MissionState {
        match self.phase {
            Phase::Done(s) => s,
            _ => MissionState::Running,
        }
    }

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
    fn step_done(&mut self, step: usize, at: Pose2, now: u64) -> Vec<Output> {
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

    /// Which level of servoing is steering now.
    fn servo_level(&self) -> ServoLevel {
        match self.phase {
            Phase::Preempted { .. } => ServoLevel::Goal,
            Phase::Refining { .. } => ServoLevel::Plan,
            _ if !self.recovery.is_empty() => ServoLevel::Goal,
            _ if self.leg.as_ref().is_some_and(|l| l.servo.is_some()) => ServoLevel::Action,
            _ => ServoLevel::None,
        }
    }

    fn status(&mut self, stamp_ns: u64) -> MissionStatus {
        self.seq += 1;
        let step = match self.phase {
            Phase::Waiting => 0,
            Phase::Executing { step, .. }
            | Phase::Looking { step, .. }
            | Phase::Refining { step, .. }
            | Phase::Preempted { step, .. } => step,
            Phase::Done(_) => self.mission.steps.len(),
        };
        MissionStatus {
            header: Header::new(self.seq, stamp_ns),
            state: self.state() as u32,
            step: step as u32,
            step_count: self.mission.steps.len() as u32,
            servo: self.servo_level() as u32,
            estimated: self.estimated,
            goal: self.goal,
            sonar_rings_seen: self.sonar_rings_seen,
            detections_seen: self.detections_seen,
            maps_seen: self.maps_seen,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mission(timeout_s: f64) -> Mission {
        Mission {
            description: "t".into(),
            timeout_s,
            servo: None,
            refine: None,
            ptrans: None,
            docking: None,
            poles: None,
            steps: vec![
                Step { move_m: Some(2.0), ..Step::default() },
                Step { turn_deg: Some(90.0), ..Step::default() },
            ],
        }
    }

    fn odo(stamp_s: f64, x_m: f64, cmd: MotionCommand, accepted: bool, moving: bool) -> Odometry {
        Odometry {
            header: Header::new(1, (stamp_s * 1e9) as u64),
            world_from_robot: Pose2 { x_m, ..Default::default() },
            command: cmd,
            command_accepted: u32::from(accepted),
            moving: u32::from(moving),
            ..Default::default()
        }
    }

    #[test]
    fn the_script_runs_step_by_step_to_success() {
        let mut e = Executive::new(mission(60.0), Vec::new());
        let out = e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false));
        let Output::Command(mv) = out[0] else { panic!("{out:?}") };
        assert_eq!((mv.kind, mv.distance_m, mv.command_id), (CommandKind::Move as u32, 2.0, 1));
        // Accepted but still moving: nothing new.
        assert_eq!(e.on_odometry(&odo(1.0, 0.3, mv, true, true)).len(), 1);
        let out = e.on_odometry(&odo(7.0, 1.9, mv, true, false));
        let Output::Command(turn) = out[0] else { panic!("{out:?}") };
        assert_eq!((turn.kind, turn.command_id), (CommandKind::Turn as u32, 2));
        assert!((turn.angle_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        let out = e.on_odometry(&odo(10.0, 1.9, turn, true, false));
        let Output::Status(s) = out[0] else { panic!("{out:?}") };
        assert_eq!((s.state(), s.step, s.step_count), (Some(MissionState::Succeeded), 2, 2));
        assert!(
            (s.goal.x_m - 2.0).abs() < 1e-12
                && (s.goal.heading_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12
        );
    }

    #[test]
    fn after_a_reflex_the_interrupted_step_is_finished_from_where_the_robot_is() {
        let one = Mission { steps: vec![Step { move_m: Some(4.0), ..Step::default() }], ..mission(60.0) };
        let mut e = Executive::new(one, Vec::new());
        let out = e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false));
        let Output::Command(mv) = out[0] else { panic!("{out:?}") };
        // The sonar's panic-avoid takes over 2 m in, and keeps the vehicle busy for a while.
        let reflex =
            |id: u32| MotionCommand { command_id: 0x8000_0000 | id, urgent: 1, ..MotionCommand::default() };
        assert_eq!(e.on_odometry(&odo(1.0, 1.0, mv, true, true)).len(), 1);
        assert_eq!(e.on_odometry(&odo(7.0, 2.0, reflex(1), true, false)).len(), 1);
        assert_eq!(e.on_odometry(&odo(8.0, 2.0, reflex(2), true, true)).len(), 1);
        assert_eq!(e.preemptions, 1);
        let mut at = odo(12.0, 2.0, reflex(3), true, false);
        at.world_from_robot = Pose2 { x_m: 2.0, y_m: 0.9, heading_rad: std::f64::consts::FRAC_PI_2 };
        assert_eq!(e.on_odometry(&at).len(), 1, "quiet for less than 2 s");
        at.header.stamp_ns = 14_500_000_000;
        let out = e.on_odometry(&at);
        let Output::Command(turn) = out[0] else { panic!("{out:?}") };
        assert_eq!(turn.kind, CommandKind::Turn as u32);
        assert!((turn.angle_rad - (-std::f64::consts::FRAC_PI_2 + (-0.9f64).atan2(2.0))).abs() < 1e-9);
        // The vehicle still reports the reflex's last command: no new preemption.
        assert_eq!(e.on_odometry(&at).len(), 1);
        let out = e.on_odometry(&odo(16.0, 2.0, turn, true, false));
        let Output::Command(go) = out[0] else { panic!("{out:?}") };
        assert!(go.kind == CommandKind::Move as u32 && (go.distance_m - 2.0f64.hypot(0.9)).abs() < 1e-9);
        let out = e.on_odometry(&odo(24.0, 4.0, go, true, false));
        let Output::Command(last) = out[0] else { panic!("{out:?}") };
        assert_eq!(last.kind, CommandKind::Turn as u32);
        e.on_odometry(&odo(26.0, 4.0, last, true, false));
        assert_eq!((e.state(), e.preemptions), (MissionState::Succeeded, 1));
    }

    #[test]
    fn a_mission_past_its_time_fails_and_stops_the_robot() {
        let mut e = Executive::new(mission(5.0), Vec::new());
        let out = e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false));
        let Output::Command(mv) = out[0] else { panic!("{out:?}") };
        let out = e.on_odometry(&odo(6.0, 1.0, mv, true, true));
        assert!(matches!(out[0], Output::Command(c) if c.kind == CommandKind::Stop as u32));
        assert_eq!(e.state(), MissionState::Failed);
    }
}
