"""The topic table of `crates/msgs/src/topics.rs`: every topic's name, payload type and QoS."""

from dataclasses import dataclass
from typing import Dict, Optional, Type

from . import msgs


@dataclass(frozen=True)
class Qos:
    """Queue sizing of a topic (`harvey_msgs::Qos`)."""

    buffer: int
    borrowed: int
    history: int
    max_publishers: int
    max_subscribers: int

    @property
    def max_nodes(self) -> int:
        """What Harvey's bus gives the services of a topic (`harvey_bus` `max_nodes`)."""
        return self.max_publishers + self.max_subscribers + 2


STATE = Qos(buffer=16, borrowed=2, history=16, max_publishers=4, max_subscribers=8)
FRAMES = Qos(buffer=2, borrowed=1, history=1, max_publishers=1, max_subscribers=6)
LOG = Qos(buffer=16, borrowed=2, history=16, max_publishers=16, max_subscribers=8)
CLOCK = Qos(buffer=8, borrowed=1, history=0, max_publishers=2, max_subscribers=4)


@dataclass(frozen=True)
class Topic:
    """A topic: its name, its payload type (for frames: the `FrameHeader` user header of a
    `[u8]` slice) and its QoS."""

    name: str
    payload: Type[msgs.Message]
    qos: Qos
    frames: bool = False


SIM_TRUTH = Topic("sim/truth", msgs.TruePose, STATE)
DRV_SONAR_RAW = Topic("drv/sonar_raw", msgs.SonarRaw, STATE)
DRV_ENCODERS_RAW = Topic("drv/encoders_raw", msgs.EncodersRaw, STATE)
VEHICLE_COMMAND = Topic("vehicle/command", msgs.MotionCommand, STATE)
VEHICLE_REFLEX = Topic("vehicle/reflex", msgs.MotionCommand, STATE)
SONAR_RING = Topic("sonar/ring", msgs.SonarRing, STATE)
ODOMETRY = Topic("odometry", msgs.Odometry, STATE)
VISION_DETECTIONS = Topic("vision/detections", msgs.Detections, STATE)
UMS_MAP = Topic("ums/map", msgs.UncertaintyMap, STATE)
VISION_SIGHTINGS = Topic("vision/sightings", msgs.LandmarkSighting, STATE)
UMS_EXPECTATIONS = Topic("ums/expectations", msgs.Expectation, STATE)
EXECUTIVE_STATUS = Topic("executive/status", msgs.MissionStatus, STATE)
EXECUTIVE_SERVO = Topic("executive/servo", msgs.ServoCorrection, STATE)
EXECUTIVE_POSE = Topic("executive/pose", msgs.PoseFix, STATE)
EXECUTIVE_PLAN = Topic("executive/plan", msgs.PlanSketch, STATE)
EXECUTIVE_BEHAVIOUR = Topic("executive/behaviour", msgs.BehaviourState, STATE)
VISION_REQUESTS = Topic("vision/requests", msgs.VisionRequest, STATE)
VISION_RESULTS = Topic("vision/results", msgs.VisionResult, STATE)
ROSOUT = Topic("rosout", msgs.LogLine, LOG)
CAMERA_FRAME = Topic("camera/frame", msgs.FrameHeader, FRAMES, frames=True)

# Every recorded topic, in the order of `topics::ALL`.
ALL: Dict[str, Topic] = {
    t.name: t
    for t in (
        SIM_TRUTH,
        DRV_SONAR_RAW,
        DRV_ENCODERS_RAW,
        VEHICLE_COMMAND,
        VEHICLE_REFLEX,
        SONAR_RING,
        ODOMETRY,
        VISION_DETECTIONS,
        UMS_MAP,
        VISION_SIGHTINGS,
        UMS_EXPECTATIONS,
        EXECUTIVE_STATUS,
        EXECUTIVE_SERVO,
        EXECUTIVE_POSE,
        EXECUTIVE_PLAN,
        EXECUTIVE_BEHAVIOUR,
        VISION_REQUESTS,
        VISION_RESULTS,
        ROSOUT,
        CAMERA_FRAME,
    )
}


def clock_progress(party: str) -> Topic:
    """The progress topic of clock party `party` (deterministic mode): bus plumbing, not in
    `ALL` and not recorded."""
    return Topic(f"clock/{party}", msgs.Progress, CLOCK)


def lookup(name: str) -> Optional[Topic]:
    """The topic called `name` (a leading `/`, as in recordings, is allowed)."""
    name = name.lstrip("/")
    if name in ALL:
        return ALL[name]
    if name.startswith("clock/") and len(name) > len("clock/"):
        return clock_progress(name[len("clock/") :])
    return None
