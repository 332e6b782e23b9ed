"""The oracle values of `services/zenoh-bridge/src/ros2/` tests, from third-party code:

- each recorded topic's RIHS01 type hash by Python `rosbags` (0.11): the schema text the
  recording carries for the topic (Harvey's `full_text`, what `harvey_cdr::full_text` gives)
  is registered with `get_types_from_msg` in an empty type store, then `hash_rihs01`;
- the stock ROS 2 Jazzy hashes of the standard types Harvey embeds (rosbags' Jazzy store);
- rmw_zenoh's attachment for one sample, serialised by Python `eclipse-zenoh`'s
  `zenoh.ext.z_serialize` (zenoh-ext, the serializer `zenoh::ext::Serializer` wraps).

The recording must be this build's (`harvey replay` refuses one whose schemas differ); the
reference recording is the default.

Usage: .venv/bin/python scripts/rihs01_oracle.py [RUN.MCAP]
"""
import sys
from pathlib import Path

from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

# Every shape a field can take (not `char`: rosbags makes it FIELD_TYPE_CHAR, rosidl `uint8`;
# not `wstring`, which rosbags does not take).
PROBE = """# A probe of every shape
int32 LIMIT=10
string NAME="a # b"
string<=8 name "x" # bounded
float64[3] xyz
probe_msgs/Part[<=4] parts
Part one
Header header
uint8[] data
byte b
bool flag true
int8 x
================================================================================
MSG: probe_msgs/Part
string<=5[2] tags
int16[<=3] small
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
"""

STANDARD = [
    "builtin_interfaces/msg/Time",
    "std_msgs/msg/Header",
    "std_msgs/msg/String",
    "std_msgs/msg/Empty",
    "sensor_msgs/msg/Image",
    "sensor_msgs/msg/CameraInfo",
    "rcl_interfaces/msg/Log",
    "tf2_msgs/msg/TFMessage",
    "visualization_msgs/msg/MarkerArray",
]


def main() -> int:
    path = Path(sys.argv[1] if len(sys.argv) > 1 else "recordings/reference/default.mcap")
    print(f"// rosbags hash_rihs01 of the schemas in {path}")
    with AnyReader([path]) as reader:
        for c in sorted(reader.connections, key=lambda c: c.id):
            store = get_typestore(Stores.EMPTY)
            store.register(get_types_from_msg(c.msgdef.data, c.msgtype))
            print(f'("{c.topic.lstrip("/")}", "{c.msgtype}", "{store.hash_rihs01(c.msgtype)}"),')
    store = get_typestore(Stores.EMPTY)
    store.register(get_types_from_msg(PROBE, "probe_msgs/msg/Probe"))
    print(f'// the probe: "{store.hash_rihs01("probe_msgs/msg/Probe")}"')
    jazzy = get_typestore(Stores.ROS2_JAZZY)
    print("// rosbags' ROS 2 Jazzy store")
    for name in STANDARD:
        print(f'("{name}", "{jazzy.hash_rihs01(name)}"),')
    try:
        from zenoh.ext import Int64, UInt8, z_serialize
    except ImportError:
        print("// eclipse-zenoh is not installed: no attachment")
        return 0
    seq, stamp, gid = 7, 1_700_000_000_123_456_789, list(range(0xA0, 0xB0))
    data = z_serialize((Int64(seq), Int64(stamp), [UInt8(b) for b in gid])).to_bytes()
    print(f"// attachment(seq {seq}, stamp {stamp}, gid a0..af) by zenoh.ext.z_serialize")
    print(bytes(data).hex())
    return 0


if __name__ == "__main__":
    sys.exit(main())
