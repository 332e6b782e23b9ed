//! The executive's logic: its state (the mission's script, the phase of the step under way, what
//! it believes) and the status it reports. `script.rs` runs the TURN/MOVE script against
//! odometry, `refining.rs` its pose fixes, `monitor.rs` plan-and-monitor, which appends the steps,
//! and `behaviour.rs` the acceptor-sequenced behaviours, which drive instead of a script.

pub mod behaviour;
pub mod dock_pose;
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
pub mod script;
pub mod sequenced;
pub mod servo;

use harvey_msgs::{BehaviourState, PlanSketch, PoseFix, SonarRing};
use harvey_msgs::{
    CommandKind, Header, MissionState, MissionStatus, MotionCommand, Pose2, ServoCorrection, ServoLevel,
    VisionRequest,
};
use leg::{Leg, ServoSetup};
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
mod tests;
