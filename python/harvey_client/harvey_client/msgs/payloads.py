"""The fixed-size payloads of every non-image topic, as `crates/msgs/src/payloads.rs`."""

from .base import Header, Message, Pose2, c_f32, c_f64, c_u32, c_u64

SONAR_SENSORS = 24
SONAR_BANK_SIZE = 8
MAX_FEATURES = 32
MAX_POLYGON_VERTICES = 32

# Enumerations carried as their `u32` discriminants.
COMMAND_KINDS = {0: "stop", 1: "move", 2: "turn", 3: "velocity"}
SIGHTING_KINDS = {0: "not_found", 1: "bearing", 2: "bearing_range", 3: "ground_line"}
MISSION_STATES = {0: "running", 1: "succeeded", 2: "failed"}


class TruePose(Message):
    _fields_ = [("header", Header), ("world_from_robot", Pose2)]
    _type_name = "harvey_msgs/TruePose"


class Progress(Message):
    _fields_ = [("header", Header)]
    _type_name = "harvey_msgs/Progress"


class SonarRaw(Message):
    _fields_ = [
        ("header", Header),
        ("bank", c_u32),
        ("echo_mask", c_u32),
        ("range_m", c_f32 * SONAR_BANK_SIZE),
    ]
    _type_name = "harvey_msgs/SonarRaw"


class SonarRing(Message):
    _fields_ = [
        ("header", Header),
        ("range_m", c_f32 * SONAR_SENSORS),
        ("bearing_rad", c_f32 * SONAR_SENSORS),
        ("reading_stamp_ns", c_u64 * SONAR_SENSORS),
        ("valid_mask", c_u32),
        ("panic_stop", c_u32),
    ]
    _type_name = "harvey_msgs/SonarRing"


class EncodersRaw(Message):
    _fields_ = [
        ("header", Header),
        ("x_m", c_f64),
        ("y_m", c_f64),
        ("heading_rad", c_f64),
        ("moving", c_u32),
        ("command_id", c_u32),
    ]
    _type_name = "harvey_msgs/EncodersRaw"


class MotionCommand(Message):
    _fields_ = [
        ("header", Header),
        ("kind", c_u32),
        ("urgent", c_u32),
        ("distance_m", c_f64),
        ("angle_rad", c_f64),
        ("linear_mps", c_f64),
        ("angular_radps", c_f64),
        ("command_id", c_u32),
        ("reserved", c_u32),
    ]
    _type_name = "harvey_msgs/MotionCommand"


class Odometry(Message):
    _fields_ = [
        ("header", Header),
        ("world_from_robot", Pose2),
        ("travelled_m", c_f64),
        ("turned_rad", c_f64),
        ("command", MotionCommand),
        ("moving", c_u32),
        ("command_accepted", c_u32),
    ]
    _type_name = "harvey_msgs/Odometry"


class Feature(Message):
    _fields_ = [("x_px", c_f32), ("y_px", c_f32), ("score", c_f32), ("kind", c_u32)]
    _type_name = "harvey_msgs/Feature"


class Detections(Message):
    _fields_ = [
        ("header", Header),
        ("frame_seq", c_u64),
        ("algorithm", c_u32),
        ("count", c_u32),
        ("confidence", c_f32),
        ("reserved", c_u32),
        ("features", Feature * MAX_FEATURES),
    ]
    _type_name = "harvey_msgs/Detections"


class UncertaintyMap(Message):
    _fields_ = [
        ("header", Header),
        ("centre", Pose2),
        ("vertex_count", c_u32),
        ("lost", c_u32),
        ("vertices_m", (c_f64 * 2) * MAX_POLYGON_VERTICES),
        ("heading_cw_rad", c_f64),
        ("heading_ccw_rad", c_f64),
        ("area_m2", c_f64),
        ("missed_landmarks", c_u32),
        ("reserved", c_u32),
    ]
    _type_name = "harvey_msgs/UncertaintyMap"


class LandmarkSighting(Message):
    _fields_ = [
        ("header", Header),
        ("frame_seq", c_u64),
        ("landmark_index", c_u32),
        ("kind", c_u32),
        ("a", c_f64),
        ("a_sd", c_f64),
        ("b", c_f64),
        ("b_sd", c_f64),
    ]
    _type_name = "harvey_msgs/LandmarkSighting"


class Expectation(Message):
    _fields_ = [
        ("header", Header),
        ("landmark_index", c_u32),
        ("class", c_u32),
        ("window_px", c_f32 * 4),
        ("width_px", c_u32),
        ("height_px", c_u32),
        ("contrast", c_f32 * 4),
    ]
    _type_name = "harvey_msgs/Expectation"


class MissionStatus(Message):
    _fields_ = [
        ("header", Header),
        ("state", c_u32),
        ("step", c_u32),
        ("step_count", c_u32),
        ("servo", c_u32),
        ("estimated", Pose2),
        ("goal", Pose2),
        ("sonar_rings_seen", c_u64),
        ("detections_seen", c_u64),
        ("maps_seen", c_u64),
    ]
    _type_name = "harvey_msgs/MissionStatus"
