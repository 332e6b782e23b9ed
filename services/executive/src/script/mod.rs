//! The script runner (000 §5.5): a mission's TURN/MOVE primitives commanded one by one and
//! checked against odometry (`runner.rs`), a move perhaps driven in increments and servoed on a
//! landmark (`leg.rs`), a `refine_pose` step fixing the pose from landmark vertices
//! (`refining.rs`), and the way back to an interrupted step after a reflex (`recover.rs`). What
//! comes after the last step is the [`Sequel`]'s: nothing for a plain script, more steps for
//! plan-and-monitor.

pub(crate) mod clearance;
pub mod leg;
pub mod recover;
mod refining;
mod runner;
mod sighting;
pub mod window;

use harvey_msgs::{CommandKind, MissionState, Pose2, ServoLevel};

use crate::Output;
use crate::Progress;
use crate::mission::{self, Step};
use crate::servo::belief::Belief;
use crate::servo::vertices::RefineSetup;
use leg::{Leg, LegStep, ServoSetup};

pub use refining::WAIT_NS;

/// The executive's vision request ids start here (the vision workers' own standing requests
/// use small ids).
const REQUEST_BASE: u32 = 100;

/// What the step under way is doing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Phase {
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
    /// A sonar reflex took the vehicle during step `i`; since `since_ns` no new reflex command
    /// came and the vehicle kept still (or the way ahead was blocked when it was to go on).
    Preempted {
        step: usize,
        since_ns: u64,
    },
    Done(MissionState),
}

/// What follows a script's last step.
#[derive(Debug, Clone, PartialEq)]
pub enum More {
    /// These steps, appended to the script and begun.
    Steps(Vec<Step>),
    /// Nothing: the mission ends so.
    End(MissionState),
}

/// Where a script's further steps come from: plan-and-monitor appends them as they are needed.
pub trait Sequel {
    /// Where the mission should end, for a script of `steps` started from `at`.
    fn goal(&self, at: Pose2, steps: &[Step]) -> Pose2;

    /// The script's steps are done (or there were none) with the robot believed at `at`, after
    /// `fixes`: what comes next; anything to publish first goes to `out`.
    fn more(&mut self, at: Pose2, fixes: Fixes, now: u64, out: &mut Vec<Output>) -> More;
}

/// The pose fixes a script has made, and how well the last one placed the robot.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Fixes {
    pub count: u32,
    /// The last fix's position standard deviation, map error included
    /// (`Refined::map_position_sd_m`), m; 0 before any.
    pub last_sd_m: f64,
}

/// A script and nothing after it: the mission succeeds when its last step is done.
#[derive(Debug, Clone, Copy, Default)]
pub struct End;

impl Sequel for End {
    fn goal(&self, at: Pose2, steps: &[Step]) -> Pose2 {
        goal_of(at, steps)
    }

    fn more(&mut self, _: Pose2, _: Fixes, _: u64, _: &mut Vec<Output>) -> More {
        More::End(MissionState::Succeeded)
    }
}

/// Where a script ends when executed exactly from `start`.
pub fn goal_of(start: Pose2, steps: &[Step]) -> Pose2 {
    steps.iter().fold(start, |p, s| match (s.move_m, s.turn_deg) {
        (Some(d), _) => p.arc(d, 0.0),
        (_, Some(a)) => Pose2 { heading_rad: p.heading_rad + a.to_radians(), ..p },
        _ => p,
    })
}

/// The script under way and what it believes.
#[derive(Debug, Clone)]
pub struct Script {
    steps: Vec<Step>,
    /// `[mission.servo]`: the template and score of a leg's looks.
    servo_table: Option<mission::Servo>,
    /// Per step, what servoing it needs (resolved from the world by the set-up).
    servo: Vec<Option<ServoSetup>>,
    /// The incremental leg under way.
    pub leg: Option<Leg>,
    /// Every finished leg, for the summary.
    pub legs: Vec<Leg>,
    next_request: u32,
    /// Where the current step should leave the robot (for getting back to it after a reflex).
    step_goal: Pose2,
    /// Primitives still to run to get back to `step_goal` (or, in a leg, to `leg_anchor`),
    /// next last.
    recovery: Vec<(CommandKind, f64)>,
    /// In a leg (servoed or open loop): its step under way and the believed pose it began from.
    /// A reflex's interruption brings the robot back there and does the step again, so that a
    /// servoed leg goes on looking and correcting instead of driving to the step's goal by
    /// odometry.
    leg_anchor: Option<(Pose2, LegStep)>,
    /// The leg's step to do again once `recovery` is run.
    redo: Option<LegStep>,
    /// The latest sonar ring's way ahead and behind.
    clearance: clearance::Clearance,
    servo_seq: u64,
    /// Plan-level servoing: what `refine_pose` steps need, the vertices the current one asked
    /// for and what each look found.
    refine: Option<RefineSetup>,
    asked: Vec<usize>,
    looks: Vec<Option<[f64; 2]>>,
    /// Pose fixes made so far…
    pub fixes: u32,
    /// …and the last one's position standard deviation (m).
    fix_sd_m: f64,
    /// Odometry and the last fix.
    belief: Belief,
    /// Times a reflex interrupted the mission.
    pub preemptions: u32,
    /// The latest reflex command already dealt with (the vehicle reports it until ours is taken).
    handled_reflex: u32,
    phase: Phase,
    goal: Pose2,
    estimated: Pose2,
    next_id: u32,
}

impl Script {
    /// `steps` to run; `servo_table` the mission's `[mission.servo]`; `servo[i]` how step `i`
    /// servos (it must say so for every `servo_landmark` step).
    pub fn new(
        steps: Vec<Step>,
        servo_table: Option<mission::Servo>,
        servo: Vec<Option<ServoSetup>>,
    ) -> Self {
        Self {
            steps,
            servo_table,
            servo,
            leg: None,
            legs: Vec::new(),
            next_request: REQUEST_BASE,
            step_goal: Pose2::default(),
            recovery: Vec::new(),
            leg_anchor: None,
            redo: None,
            clearance: clearance::Clearance::default(),
            servo_seq: 0,
            refine: None,
            asked: Vec::new(),
            looks: Vec::new(),
            fixes: 0,
            fix_sd_m: 0.0,
            belief: Belief::default(),
            preemptions: 0,
            handled_reflex: 0,
            phase: Phase::Waiting,
            goal: Pose2::default(),
            estimated: Pose2::default(),
            next_id: 1,
        }
    }

    /// A sonar ring: the way ahead and behind for getting back after a reflex.
    pub fn on_sonar(&mut self, ring: &harvey_msgs::SonarRing) {
        self.clearance = clearance::Clearance::of(ring);
    }

    /// With plan-level servoing: what `refine_pose` steps need.
    pub fn with_refine(mut self, setup: RefineSetup) -> Self {
        self.refine = Some(setup);
        self
    }

    /// The steps so far (plan-and-monitor's appended ones included).
    pub fn steps(&self) -> &[Step] {
        &self.steps
    }

    pub fn state(&self) -> MissionState {
        match self.phase {
            Phase::Done(s) => s,
            _ => MissionState::Running,
        }
    }

    /// Whether the first odometry is still to come.
    pub fn waiting(&self) -> bool {
        self.phase == Phase::Waiting
    }

    /// The mission is over (its time ran out): ends the script in `state`; returns the id the
    /// stop command takes (the next command id, which is not used up).
    pub fn finish(&mut self, state: MissionState) -> u32 {
        self.phase = Phase::Done(state);
        self.next_id
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

    /// What the status reports of the script.
    pub fn progress(&self) -> Progress {
        let step = match self.phase {
            Phase::Waiting => 0,
            Phase::Executing { step, .. }
            | Phase::Looking { step, .. }
            | Phase::Refining { step, .. }
            | Phase::Preempted { step, .. } => step,
            Phase::Done(_) => self.steps.len(),
        };
        Progress {
            state: self.state(),
            step,
            step_count: self.steps.len(),
            servo: self.servo_level(),
            estimated: self.estimated,
            goal: self.goal,
        }
    }
}

#[cfg(test)]
mod tests;
