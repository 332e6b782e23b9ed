//! The topic table: every topic's name, payload type and queue sizing, in one place.

use core::marker::PhantomData;

use crate::{
    BehaviourState, Detections, EncodersRaw, Expectation, LandmarkSighting, LogLine, MissionStatus,
    MotionCommand, Odometry, PlanSketch, PoseFix, Progress, ServoCorrection, SonarRaw, SonarRing, TruePose,
    UncertaintyMap, VisionRequest, VisionResult,
};

/// Queue sizing of a topic. Every process opening the topic uses the same numbers, so the
/// first one to create it fixes them and the others match.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    /// Samples a subscriber may hold queued; the oldest is overwritten when full.
    pub buffer: usize,
    /// Samples a subscriber may hold at once while it works on them.
    pub borrowed: usize,
    /// Samples a late subscriber receives on connecting.
    pub history: usize,
    pub max_publishers: usize,
    pub max_subscribers: usize,
}

impl Qos {
    /// Small fixed-size messages: a few consumers plus the recorder and tools. A whole queue's
    /// worth of history: a restarted consumer is handed the newest messages again (the
    /// supervisor's re-offer), as many as a tick may bring (several sightings per frame, several
    /// expectations per map), and drops those its checkpoint says it has taken.
    pub const STATE: Qos =
        Qos { buffer: 16, borrowed: 2, history: 16, max_publishers: 4, max_subscribers: 8 };
    /// Camera frames: every slot costs a whole frame of shared memory, so keep them few, yet
    /// enough for the recorder, two vision workers and two observers (`harvey topic`, a Python
    /// client) besides, one spare: 6 subscribers x (2 queued + 1 held) + 1 loaned + 1 history =
    /// 20 frames (124 MB at 1080p rgb8, 6.1 MB at 640x480 mono8). The history frame is what a
    /// restarted consumer is handed again (the supervisor's re-offer, `harvey_bus` `reoffer.rs`).
    pub const FRAMES: Qos = Qos { buffer: 2, borrowed: 1, history: 1, max_publishers: 1, max_subscribers: 6 };
    /// Services' log lines (`rosout`): every service publishes on it, as ROS 2 nodes do.
    pub const LOG: Qos = Qos { buffer: 16, borrowed: 2, history: 16, max_publishers: 16, max_subscribers: 8 };
    /// A clock party's progress: read by its successor, the clock master and the supervisor
    /// (which also publishes, to start the chain and to resume it after a restart).
    pub const CLOCK: Qos = Qos { buffer: 8, borrowed: 1, history: 0, max_publishers: 2, max_subscribers: 4 };
}

/// A typed topic of fixed-size messages.
#[derive(Debug)]
pub struct Topic<T> {
    pub name: &'static str,
    pub qos: Qos,
    _payload: PhantomData<fn() -> T>,
}

impl<T> Clone for Topic<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Topic<T> {}

impl<T> Topic<T> {
    pub const fn new(name: &'static str, qos: Qos) -> Self {
        Self { name, qos, _payload: PhantomData }
    }
}

/// A topic of camera frames: `[u8]` pixels with a [`crate::FrameHeader`].
#[derive(Debug, Clone, Copy)]
pub struct FrameTopic {
    pub name: &'static str,
    pub qos: Qos,
}

pub const SIM_TRUTH: Topic<TruePose> = Topic::new("sim/truth", Qos::STATE);
pub const DRV_SONAR_RAW: Topic<SonarRaw> = Topic::new("drv/sonar_raw", Qos::STATE);
pub const DRV_ENCODERS_RAW: Topic<EncodersRaw> = Topic::new("drv/encoders_raw", Qos::STATE);
pub const VEHICLE_COMMAND: Topic<MotionCommand> = Topic::new("vehicle/command", Qos::STATE);
/// The sonar reflexes' urgent commands (001 §6.2: straight to the vehicle, over any other).
pub const VEHICLE_REFLEX: Topic<MotionCommand> = Topic::new("vehicle/reflex", Qos::STATE);
pub const SONAR_RING: Topic<SonarRing> = Topic::new("sonar/ring", Qos::STATE);
pub const ODOMETRY: Topic<Odometry> = Topic::new("odometry", Qos::STATE);
pub const VISION_DETECTIONS: Topic<Detections> = Topic::new("vision/detections", Qos::STATE);
pub const UMS_MAP: Topic<UncertaintyMap> = Topic::new("ums/map", Qos::STATE);
pub const VISION_SIGHTINGS: Topic<LandmarkSighting> = Topic::new("vision/sightings", Qos::STATE);
pub const UMS_EXPECTATIONS: Topic<Expectation> = Topic::new("ums/expectations", Qos::STATE);
pub const EXECUTIVE_STATUS: Topic<MissionStatus> = Topic::new("executive/status", Qos::STATE);
pub const EXECUTIVE_SERVO: Topic<ServoCorrection> = Topic::new("executive/servo", Qos::STATE);
pub const EXECUTIVE_POSE: Topic<PoseFix> = Topic::new("executive/pose", Qos::STATE);
pub const EXECUTIVE_PLAN: Topic<PlanSketch> = Topic::new("executive/plan", Qos::STATE);
pub const EXECUTIVE_BEHAVIOUR: Topic<BehaviourState> = Topic::new("executive/behaviour", Qos::STATE);
pub const VISION_REQUESTS: Topic<VisionRequest> = Topic::new("vision/requests", Qos::STATE);
pub const VISION_RESULTS: Topic<VisionResult> = Topic::new("vision/results", Qos::STATE);
/// Every service's warnings and errors, stamped with the tick that raised them (ROS 2's
/// `/rosout`, `rcl_interfaces/msg/Log` in a recording).
pub const ROSOUT: Topic<LogLine> = Topic::new("rosout", Qos::LOG);
pub const CAMERA_FRAME: FrameTopic = FrameTopic { name: "camera/frame", qos: Qos::FRAMES };

/// The progress topic of clock party `party` (deterministic mode), `clock/<party>`: bus
/// plumbing, not data, so it is not in [`ALL`] and is not recorded. The name is leaked: call
/// this once per party at start-up, not per message.
pub fn clock_progress(party: &str) -> Topic<Progress> {
    let name: &'static str = Box::leak(format!("clock/{party}").into_boxed_str());
    Topic::new(name, Qos::CLOCK)
}

/// Every topic's name; the recorder must record each of them.
pub const ALL: &[&str] = &[
    SIM_TRUTH.name,
    DRV_SONAR_RAW.name,
    DRV_ENCODERS_RAW.name,
    VEHICLE_COMMAND.name,
    VEHICLE_REFLEX.name,
    SONAR_RING.name,
    ODOMETRY.name,
    VISION_DETECTIONS.name,
    UMS_MAP.name,
    VISION_SIGHTINGS.name,
    UMS_EXPECTATIONS.name,
    EXECUTIVE_STATUS.name,
    EXECUTIVE_SERVO.name,
    EXECUTIVE_POSE.name,
    EXECUTIVE_PLAN.name,
    EXECUTIVE_BEHAVIOUR.name,
    VISION_REQUESTS.name,
    VISION_RESULTS.name,
    ROSOUT.name,
    CAMERA_FRAME.name,
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_names_are_unique_and_well_formed() {
        let mut names: Vec<&str> = ALL.to_vec();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), ALL.len(), "a topic name is listed twice");
        for name in ALL {
            assert!(!name.is_empty() && !name.starts_with('/') && !name.ends_with('/'), "{name}");
            assert!(name.chars().all(|c| c.is_ascii_lowercase() || "_/".contains(c)), "{name}");
        }
    }
}
