"""What the executive publishes about its own working besides its mission status (servoing,
pose refinement, plan sketch, behaviour state), as `crates/msgs/src/executive.rs`."""

from .base import Header, Message, Pose2, c_f32, c_f64, c_u32

SKETCH_PLACES = 12

# The servoing level, carried as its `u32` discriminant.
SERVO_LEVELS = {0: "none", 1: "action", 2: "plan", 3: "goal"}


class ServoCorrection(Message):
    _fields_ = [
        ("header", Header),
        ("increment", c_u32),
        ("landmark_index", c_u32),
        ("found_px", c_f32 * 2),
        ("heading_error_rad", c_f64),
        ("correction_rad", c_f64),
        ("offset_m", c_f64),
        ("shortfall_m", c_f64),
    ]
    _type_name = "harvey_msgs/ServoCorrection"


class PoseFix(Message):
    _fields_ = [
        ("header", Header),
        ("expected", Pose2),
        ("refined", Pose2),
        ("asked", c_u32),
        ("found", c_u32),
        ("kept", c_u32),
        ("reserved", c_u32),
        ("rms_px", c_f64),
    ]
    _type_name = "harvey_msgs/PoseFix"


class PlanSketch(Message):
    _fields_ = [
        ("header", Header),
        ("places_m", c_f64 * (2 * SKETCH_PLACES)),
        ("place_count", c_u32),
        ("primitive_mask", c_u32),
        ("stage", c_u32),
        ("checks", c_u32),
        ("replans", c_u32),
        ("last_outcome", c_u32),
        ("last_off_m", c_f64),
    ]
    _type_name = "harvey_msgs/PlanSketch"


class BehaviourState(Message):
    _fields_ = [
        ("header", Header),
        ("at", Pose2),
        ("fsa_state", c_u32),
        ("transitions", c_u32),
        ("last_trigger", c_u32),
        ("achieved", c_u32),
        ("vectors_mps", c_f64 * 12),
        ("linear_mps", c_f64),
        ("angular_radps", c_f64),
    ]
    _type_name = "harvey_msgs/BehaviourState"
