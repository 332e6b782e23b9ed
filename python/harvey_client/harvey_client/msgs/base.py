"""What every payload builds on, as `crates/msgs/src/lib.rs` declares it: the `Message` base
class, the `Header` every message starts with, and `Pose2` (of `crates/geometry`), with the
ctypes scalar names the payload modules use."""

import ctypes
from typing import Any, Dict

c_u8 = ctypes.c_uint8
c_u16 = ctypes.c_uint16
c_u32 = ctypes.c_uint32
c_u64 = ctypes.c_uint64
c_f32 = ctypes.c_float
c_f64 = ctypes.c_double


class Message(ctypes.Structure):
    """Base of every Harvey payload: a `#[repr(C)]` structure with a stable type name."""

    _type_name = ""

    @classmethod
    def type_name(cls) -> str:
        """The Rust `#[type_name(...)]`, what iceoryx2 matches services by."""
        return cls._type_name

    def to_dict(self) -> Dict[str, Any]:
        """The fields as plain Python values (nested structures as dicts, arrays as lists)."""
        return {name: to_python(getattr(self, name)) for name, _ in self._fields_}

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.to_dict()})"


def to_python(value: Any) -> Any:
    """A ctypes value (structure, array, scalar) as plain Python values."""
    if isinstance(value, Message):
        return value.to_dict()
    if isinstance(value, ctypes.Array):
        return [to_python(v) for v in value]
    return value


class Header(Message):
    """A per-publisher sequence number and the time the message is about (ns)."""

    _fields_ = [("seq", c_u64), ("stamp_ns", c_u64)]
    _type_name = "harvey_msgs/Header"


class Pose2(Message):
    """A planar pose: metres and radians (counter-clockwise from +x)."""

    _fields_ = [("x_m", c_f64), ("y_m", c_f64), ("heading_rad", c_f64)]
    _type_name = "harvey_msgs/Pose2"
