//! The executive's logic: the mission run in one of three modes ([`Mode`]) and the status it
//! reports. A script of TURN/MOVE primitives run against odometry (`script/`), plan-and-monitor
//! appending the steps of a `(ptrans here goal)` to a script (`plan/`), or an acceptor-sequenced
//! behaviour driving by motor schemas (`behaviours/`); perceptual servoing at its levels in
//! `servo/`. `setup.rs` builds an executive from the launch file's `[mission]` and the world.

pub mod behaviours;
pub mod mission;
pub mod node;
pub mod plan;
pub mod script;
pub mod servo;
pub mod setup;

use harvey_msgs::{
    BehaviourState, CommandKind, Header, MissionState, MissionStatus, MotionCommand, Odometry, PlanSketch,
    Pose2, PoseFix, ServoCorrection, ServoLevel, SonarRing, UncertaintyMap, VisionRequest, VisionResult,
};

use behaviours::Run;
use plan::Plan;
use script::leg::Leg;
use script::{End, Script};

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

/// How the mission is run.
#[derive(Debug, Clone)]
pub enum Mode {
    /// The mission's `[[mission.step]]`s, one after another.
    Script(Box<Script>),
    /// Plan-and-monitor, developing the mission's `[mission.ptrans]` goal into steps.
    Plan(Box<Plan>),
    /// An acceptor-sequenced behaviour (`[mission.docking]`, `[mission.poles]`).
    Sequenced(Run),
}

/// What a mode tells the status of where the mission stands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    pub state: MissionState,
    /// The step under way and the steps there are (plan-and-monitor's so far).
    pub step: usize,
    pub step_count: usize,
    /// Which level of servoing steers now.
    pub servo: ServoLevel,
    /// Where the robot is believed to be, and where the mission is taking it.
    pub estimated: Pose2,
    pub goal: Pose2,
}

/// The id the stop at a behaviour's timeout takes: the executive's first command id (a
/// behaviour numbers its own commands, so the executive's count never moved from it).
const FIRST_COMMAND_ID: u32 = 1;

/// The executive's state: the mode, the mission's clock and what it has seen.
#[derive(Debug, Clone)]
pub struct Executive {
    pub mode: Mode,
    /// Simulated seconds before the mission ends (failed, unless a behaviour did enough).
    timeout_s: f64,
    /// When the first odometry came.
    start_ns: u64,
    seq: u64,
    /// Whether the UMS's last map said lost.
    lost: bool,
    pub sonar_rings_seen: u64,
    pub detections_seen: u64,
    pub maps_seen: u64,
}

impl Executive {
    pub fn new(mode: Mode, timeout_s: f64) -> Self {
        Self {
            mode,
            timeout_s,
            start_ns: 0,
            seq: 0,
            lost: false,
            sonar_rings_seen: 0,
            detections_seen: 0,
            maps_seen: 0,
        }
    }

    pub fn state(&self) -> MissionState {
        self.progress().state
    }

    fn progress(&self) -> Progress {
        match &self.mode {
            Mode::Script(s) => s.progress(),
            Mode::Plan(p) => p.script.progress(),
            Mode::Sequenced(r) => r.progress(),
        }
    }

    /// The script the mission runs (plan-and-monitor's too); none for a behaviour.
    pub fn script(&self) -> Option<&Script> {
        match &self.mode {
            Mode::Script(s) => Some(s),
            Mode::Plan(p) => Some(&p.script),
            Mode::Sequenced(_) => None,
        }
    }

    /// Every finished incremental leg, for the summary.
    pub fn legs(&self) -> &[Leg] {
        self.script().map_or(&[], |s| &s.legs)
    }

    /// Vertical-edge detections the vision workers published, counted for the status.
    pub fn on_detections(&mut self, count: u64) {
        self.detections_seen += count;
    }

    /// An uncertainty map from the UMS: plan-and-monitor relocates when it comes to say lost.
    pub fn on_map(&mut self, m: &UncertaintyMap) {
        self.maps_seen += 1;
        let became_lost = m.lost != 0 && !self.lost;
        self.lost = m.lost != 0;
        match &mut self.mode {
            Mode::Plan(plan) if became_lost => plan.lost(),
            Mode::Sequenced(run) => run.behaviour.on_map(m),
            _ => {}
        }
    }

    /// A sonar ring (the behaviours' obstacles and ranges; a script's way out after a reflex).
    pub fn on_sonar(&mut self, r: &SonarRing) {
        self.sonar_rings_seen += 1;
        match &mut self.mode {
            Mode::Sequenced(run) => run.behaviour.on_sonar(r),
            Mode::Script(s) => s.on_sonar(r),
            Mode::Plan(p) => p.script.on_sonar(r),
        }
    }

    /// A vision result: the answer to a look or a refinement's request, or the behaviour's.
    pub fn on_vision(&mut self, r: &VisionResult) -> Vec<Output> {
        match &mut self.mode {
            Mode::Script(s) => s.on_vision(r, &mut End),
            Mode::Plan(p) => p.on_vision(r),
            Mode::Sequenced(run) => {
                run.behaviour.on_vision(r);
                Vec::new()
            }
        }
    }

    /// One odometry message: advances the mission; returns the commands and requests to send,
    /// the status last.
    pub fn on_odometry(&mut self, o: &Odometry) -> Vec<Output> {
        let now = o.header.stamp_ns;
        let waiting = match &self.mode {
            Mode::Script(s) => s.waiting(),
            Mode::Plan(p) => p.script.waiting(),
            Mode::Sequenced(r) => r.waiting(),
        };
        if waiting {
            self.start_ns = now;
        }
        let mut out = match &mut self.mode {
            Mode::Script(s) => s.on_odometry(o, &mut End),
            Mode::Plan(p) => p.on_odometry(o),
            Mode::Sequenced(r) => r.on_odometry(o),
        };
        let running = self.state() == MissionState::Running;
        if running && now.saturating_sub(self.start_ns) as f64 > self.timeout_s * 1e9 {
            let id = match &mut self.mode {
                Mode::Script(s) => s.finish(MissionState::Failed),
                Mode::Plan(p) => p.script.finish(MissionState::Failed),
                Mode::Sequenced(r) => {
                    r.finish();
                    FIRST_COMMAND_ID
                }
            };
            out.push(Output::Command(MotionCommand {
                header: Header::new(u64::from(id), now),
                kind: CommandKind::Stop as u32,
                command_id: id,
                ..Default::default()
            }));
        }
        out.push(Output::Status(self.status(now)));
        out
    }

    fn status(&mut self, stamp_ns: u64) -> MissionStatus {
        self.seq += 1;
        let p = self.progress();
        MissionStatus {
            header: Header::new(self.seq, stamp_ns),
            state: p.state as u32,
            step: p.step as u32,
            step_count: p.step_count as u32,
            servo: p.servo as u32,
            estimated: p.estimated,
            goal: p.goal,
            sonar_rings_seen: self.sonar_rings_seen,
            detections_seen: self.detections_seen,
            maps_seen: self.maps_seen,
        }
    }
}
