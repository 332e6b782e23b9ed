//! The acceptor-sequenced behaviours a mission may run instead of a script or a plan (004):
//! docking and the pole hunt, behind one face for the executive.

use harvey_msgs::{BehaviourState, MotionCommand, Pose2, SonarRing, VisionRequest, VisionResult};

use crate::docking::Docking;
use crate::pole_hunt::PoleHunt;

#[derive(Debug, Clone)]
pub enum Behaviour {
    Docking(Box<Docking>),
    Poles(Box<PoleHunt>),
}

impl Behaviour {
    pub fn on_sonar(&mut self, r: &SonarRing) {
        match self {
            Self::Docking(d) => d.on_sonar(r),
            Self::Poles(p) => p.on_sonar(r),
        }
    }

    pub fn on_vision(&mut self, r: &VisionResult) {
        match self {
            Self::Docking(d) => d.on_vision(r),
            Self::Poles(p) => p.on_vision(r),
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
        }
    }

    /// Whether it is over, and well.
    pub fn done(&self) -> Option<bool> {
        match self {
            Self::Docking(d) => d.done,
            Self::Poles(p) => p.done,
        }
    }

    /// Whether the mission counts as succeeded if its time runs out now.
    pub fn enough_at_timeout(&self) -> bool {
        match self {
            Self::Docking(_) => false,
            Self::Poles(p) => p.enough(),
        }
    }

    /// Where the robot is believed to be, and where it is going.
    pub fn believed(&self, odometry: Pose2) -> Pose2 {
        match self {
            Self::Docking(d) => d.believed(),
            Self::Poles(_) => odometry,
        }
    }

    pub fn goal_pose(&self) -> Pose2 {
        match self {
            Self::Docking(d) => d.goal_pose(),
            Self::Poles(p) => p.goal_pose(),
        }
    }
}
