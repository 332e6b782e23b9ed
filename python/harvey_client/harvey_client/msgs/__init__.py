"""Harvey's wire types as ctypes structures, field for field the `#[repr(C)]` payloads of
`crates/msgs/src/*.rs` (and `Pose2` of `crates/geometry`), in modules as the Rust
definitions are split: `base` (`lib.rs`: `Message`, `Header`, `Pose2`), `payloads`, `executive`,
`vision`, `log` and `frame`.

Each class's `type_name()` is the Rust `#[type_name("...")]`: iceoryx2 compares it, the size and
the alignment when a service is opened, and refuses (`IncompatibleTypes`) on any difference.
`tests/python_client/layout.rs` checks every size, alignment and field offset against the Rust
types.
"""

import ctypes
from typing import Any, Dict, List, Type

# The names `harvey_client.msgs` has always offered, from the modules that define them.
from .base import (  # noqa: F401
    Header,
    Message,
    Pose2,
    c_f32,
    c_f64,
    c_u8,
    c_u16,
    c_u32,
    c_u64,
    to_python,
)
from .executive import (  # noqa: F401
    SERVO_LEVELS,
    SKETCH_PLACES,
    BehaviourState,
    PlanSketch,
    PoseFix,
    ServoCorrection,
)
from .frame import BYTES_PER_PIXEL, ENCODINGS, FrameHeader  # noqa: F401
from .log import LOG_LEVELS, LOG_NAME_BYTES, LOG_TEXT_BYTES, LogLine  # noqa: F401
from .payloads import (  # noqa: F401
    COMMAND_KINDS,
    MAX_FEATURES,
    MAX_POLYGON_VERTICES,
    MISSION_STATES,
    SIGHTING_KINDS,
    SONAR_BANK_SIZE,
    SONAR_SENSORS,
    Detections,
    EncodersRaw,
    Expectation,
    Feature,
    LandmarkSighting,
    MissionStatus,
    MotionCommand,
    Odometry,
    Progress,
    SonarRaw,
    SonarRing,
    TruePose,
    UncertaintyMap,
)
from .vision import MAX_VISION_ITEMS, VisionItem, VisionRequest, VisionResult  # noqa: F401

# Every payload type, by class name (the Rust type's name).
ALL_TYPES: Dict[str, Type[Message]] = {
    t.__name__: t
    for t in (
        Header,
        Pose2,
        TruePose,
        Progress,
        SonarRaw,
        SonarRing,
        EncodersRaw,
        MotionCommand,
        Odometry,
        Feature,
        Detections,
        UncertaintyMap,
        LandmarkSighting,
        Expectation,
        MissionStatus,
        ServoCorrection,
        PoseFix,
        PlanSketch,
        BehaviourState,
        VisionRequest,
        VisionItem,
        VisionResult,
        LogLine,
        FrameHeader,
    )
}


def layouts() -> List[Dict[str, Any]]:
    """Every type's layout as `tests/python_client/layout.rs` prints Rust's: name, type name, size,
    alignment and each field's offset and size."""
    out = []
    for name, t in ALL_TYPES.items():
        fields = [
            {"name": f, "offset": getattr(t, f).offset, "size": getattr(t, f).size}
            for f, _ in t._fields_
        ]
        out.append(
            {
                "name": name,
                "type_name": t.type_name(),
                "size": ctypes.sizeof(t),
                "align": ctypes.alignment(t),
                "fields": fields,
            }
        )
    return out


__all__ = [
    "Message",
    "ALL_TYPES",
    "layouts",
    "to_python",
    "SONAR_SENSORS",
    "SONAR_BANK_SIZE",
    "MAX_FEATURES",
    "MAX_POLYGON_VERTICES",
    "SKETCH_PLACES",
    "MAX_VISION_ITEMS",
    "LOG_NAME_BYTES",
    "LOG_TEXT_BYTES",
] + list(ALL_TYPES)
