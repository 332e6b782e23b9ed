//! The acceptor-sequenced behaviours a mission may run instead of a script or a plan (004):
//! docking and the pole hunt, CMU's stop-go-stop navigation (003) and door finding by sonar
//! (001 §3.2), path following (001 §2.1) and obstacle avoidance by depth from motion (001 §2.3),
//! behind one face, and
//! run as the executive's mode.

use harvey_msgs::{
    BehaviourState, MissionState, MotionCommand, Odometry, Pose2, ServoLevel, SonarRing, UncertaintyMap,
    VisionRequest, VisionResult,
};

use super::depth_obstacles::DepthObstacles;
use super::docking::Docking;
use super::door_finding::DoorFinding;
use super::neptune::Neptune;
use super::path_follow::PathFollow;
use super::pole_hunt::PoleHunt;
use crate::{Output, Progress};

#[derive(Debug, Clone)]
pub enum Behaviour {
    Docking(Box<Docking>),
    Poles(Box<PoleHunt>),
    Neptune(Box<Neptune>),
    Door(Box<DoorFinding>),
    Path(Box<PathFollow>),
    Depth(Box<DepthObstacles>),
}

impl Behaviour {
    pub fn on_sonar(&mut self, r: &SonarRing) {
        match self {
            Self::Docking(d) => d.on_sonar(r),
            Self::Poles(p) => p.on_sonar(r),
            Self::Neptune(n) => n.on_sonar(r),
            Self::Door(d) => d.on_sonar(r),
            Self::Depth(d) => d.on_sonar(r),
            Self::Path(_) => {}
        }
    }

    /// The UMS's newest map: docking judges its first pose fix by it, path following takes its
    /// pose.
    pub fn on_map(&mut self, m: &UncertaintyMap) {
        match self {
            Self::Docking(d) => d.on_map(m),
            Self::Path(p) => p.on_map(m),
            _ => {}
        }
    }

    pub fn on_vision(&mut self, r: &VisionResult) {
        match self {
            Self::Docking(d) => d.on_vision(r),
            Self::Poles(p) => p.on_vision(r),
            Self::Neptune(n) => n.on_vision(r),
            Self::Path(p) => p.on_vision(r),
            Self::Depth(d) => d.on_vision(r),
            Self::Door(_) => {}
        }
    }

    /// One odometry tick: the request to send, the velocity command and the state to publish.
    pub fn on_odometry(
        &mut self,
        odometry: Pose2,
        now: u64,
    ) -> (Option<VisionRequest>, MotionCommand, BehaviourState) {
        match self {
            Self::Docking(d) => d.on_odometry(odometry, now),
            Self::Poles(p) => p.on_odometry(odometry, now),
            Self::Neptune(n) => n.on_odometry(odometry, now),
            Self::Path(p) => p.on_odometry(odometry, now),
            Self::Depth(d) => d.on_odometry(odometry, now),
            Self::Door(d) => {
                let (command, state) = d.on_odometry(odometry, now);
                (None, command, state)
            }
        }
    }

    /// Whether it is over, and well.
    pub fn done(&self) -> Option<bool> {
        match self {
            Self::Docking(d) => d.done,
            Self::Poles(p) => p.done,
            Self::Neptune(n) => n.done,
            Self::Door(d) => d.done,
            Self::Path(p) => p.done,
            Self::Depth(d) => d.done,
        }
    }

    /// Whether the mission counts as succeeded if its time runs out now.
    pub fn enough_at_timeout(&self) -> bool {
        match self {
            Self::Docking(_) | Self::Neptune(_) | Self::Door(_) | Self::Path(_) | Self::Depth(_) => false,
            Self::Poles(p) => p.enough(),
        }
    }

    /// Where the robot is believed to be, and where it is going.
    pub fn believed(&self, odometry: Pose2) -> Pose2 {
        match self {
            Self::Docking(d) => d.believed(),
            Self::Neptune(n) => n.believed(),
            Self::Path(p) => p.believed(),
            Self::Depth(d) => d.believed(),
            Self::Poles(_) | Self::Door(_) => odometry,
        }
    }

    pub fn goal_pose(&self) -> Pose2 {
        match self {
            Self::Docking(d) => d.goal_pose(),
            Self::Poles(p) => p.goal_pose(),
            Self::Neptune(n) => n.goal_pose(),
            Self::Door(d) => d.goal_pose(),
            Self::Path(p) => p.goal_pose(),
            Self::Depth(d) => d.goal_pose(),
        }
    }
}

/// Where a behaviour run as the mission stands.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stage {
    /// No odometry yet.
    Waiting,
    Running,
    Done(MissionState),
}

/// A behaviour as the executive's mode: started by the first odometry, over when it says so
/// (or when the mission's time runs out).
#[derive(Debug, Clone)]
pub struct Run {
    pub behaviour: Behaviour,
    stage: Stage,
    estimated: Pose2,
    goal: Pose2,
}

impl Run {
    pub fn new(behaviour: Behaviour) -> Self {
        Self { behaviour, stage: Stage::Waiting, estimated: Pose2::default(), goal: Pose2::default() }
    }

    pub fn state(&self) -> MissionState {
        match self.stage {
            Stage::Done(s) => s,
            _ => MissionState::Running,
        }
    }

    /// Whether the first odometry is still to come.
    pub fn waiting(&self) -> bool {
        self.stage == Stage::Waiting
    }

    /// The mission's time ran out: over, well if the behaviour did enough.
    pub fn finish(&mut self) {
        let enough = self.behaviour.enough_at_timeout();
        self.stage = Stage::Done(if enough { MissionState::Succeeded } else { MissionState::Failed });
    }

    /// One odometry tick: the behaviour's request, velocity command and state, while it runs.
    pub fn on_odometry(&mut self, o: &Odometry) -> Vec<Output> {
        let (at, now) = (o.world_from_robot, o.header.stamp_ns);
        self.estimated = at;
        if self.stage == Stage::Waiting {
            self.stage = Stage::Running;
        }
        let mut out = Vec::new();
        if self.stage == Stage::Running {
            let b = &mut self.behaviour;
            let (look, command, state) = b.on_odometry(at, now);
            (self.estimated, self.goal) = (b.believed(at), b.goal_pose());
            out.extend(look.map(Output::Look));
            out.push(Output::Command(command));
            out.push(Output::Behaviour(state));
            if let Some(well) = b.done() {
                self.stage = Stage::Done(if well { MissionState::Succeeded } else { MissionState::Failed });
            }
        }
        out
    }

    /// What the status reports: a behaviour has no script steps, and servos on nothing the
    /// status names.
    pub fn progress(&self) -> Progress {
        Progress {
            state: self.state(),
            step: 0,
            step_count: 0,
            servo: ServoLevel::None,
            estimated: self.estimated,
            goal: self.goal,
        }
    }
}
