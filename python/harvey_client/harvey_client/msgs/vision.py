"""The vision workers' request/result protocol (`vision/requests`, `vision/results`), as
`crates/msgs/src/vision.rs`."""

from .base import Header, Message, Pose2, c_f32, c_u32, c_u64

MAX_VISION_ITEMS = 32


class VisionRequest(Message):
    _fields_ = [
        ("header", Header),
        ("request_id", c_u32),
        ("algorithm", c_u32),
        ("standing", c_u32),
        ("landmark_index", c_u32),
        ("expected", Pose2),
        ("window_px", c_f32 * 4),
        ("params", c_f32 * 8),
    ]
    _type_name = "harvey_msgs/VisionRequest"


class VisionItem(Message):
    _fields_ = [("values", c_f32 * 6)]
    _type_name = "harvey_msgs/VisionItem"


class VisionResult(Message):
    _fields_ = [
        ("header", Header),
        ("frame_seq", c_u64),
        ("request_id", c_u32),
        ("algorithm", c_u32),
        ("status", c_u32),
        ("found", c_u32),
        ("count", c_u32),
        ("reserved", c_u32),
        ("items", VisionItem * MAX_VISION_ITEMS),
    ]
    _type_name = "harvey_msgs/VisionResult"
