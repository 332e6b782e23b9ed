"""Third-party check that a Harvey recording places everything in 3D, as Foxglove's 3D panel and
RViz need: `rosbags` (its own CDR decoder, the recording's embedded schemas) decodes every message,
the standard types' definitions hash (RIHS01) to ROS 2 Jazzy's, and every message's `frame_id`
reaches `world` through `/tf_static` and `/tf` transforms stamped no later than the message.

Usage: check_tf.py RUN.MCAP
"""
import sys
from collections import Counter, defaultdict
from pathlib import Path

from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

# The standard messages a Harvey recording carries, which must be Jazzy's to the field.
STANDARD = [
    "sensor_msgs/msg/Image",
    "sensor_msgs/msg/CameraInfo",
    "rcl_interfaces/msg/Log",
    "tf2_msgs/msg/TFMessage",
    "visualization_msgs/msg/MarkerArray",
]


def frame_ids(msg, out):
    """The frame_ids a viewer places a decoded message by: its header's, or each marker's."""
    for m in getattr(msg, "markers", None) or [msg]:
        header = getattr(m, "header", None)
        if header is not None and hasattr(header, "frame_id"):
            out.append((header.frame_id, header.stamp.sec * 10**9 + header.stamp.nanosec))


def main() -> int:
    path = Path(sys.argv[1])
    failures = []
    jazzy = get_typestore(Stores.ROS2_JAZZY)
    with AnyReader([path]) as reader:
        # Each channel's own definition (its dependencies appended, as rosbag2 does), hashed as
        # ROS 2 does, against Jazzy's.
        for conn in reader.connections:
            if conn.msgtype in STANDARD:
                own = get_typestore(Stores.EMPTY)
                own.register(get_types_from_msg(conn.msgdef.data, conn.msgtype))
                try:
                    ours = own.hash_rihs01(conn.msgtype)
                except KeyError as missing:
                    failures.append(f"{conn.topic}: its {conn.msgtype} definition lacks {missing}")
                    continue
                if ours != jazzy.hash_rihs01(conn.msgtype):
                    failures.append(f"{conn.topic}: {conn.msgtype} differs from ROS 2 Jazzy's")
        edges = defaultdict(list)  # child -> [(stamp, parent)]
        static = {}
        stamped = []  # (topic, frame_id, stamp)
        counts = Counter()
        for conn, _, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            counts[conn.topic] += 1
            if conn.topic in ("/tf", "/tf_static"):
                for t in msg.transforms:
                    stamp = t.header.stamp.sec * 10**9 + t.header.stamp.nanosec
                    if conn.topic == "/tf_static":
                        static[t.child_frame_id] = t.header.frame_id
                    else:
                        edges[t.child_frame_id].append((stamp, t.header.frame_id))
                continue
            found = []
            frame_ids(msg, found)
            stamped.extend((conn.topic, f, s) for f, s in found)
    for child in edges:
        edges[child].sort()

    def reaches_world(frame, stamp):
        seen = set()
        while frame != "world":
            if frame in seen:
                return False
            seen.add(frame)
            if frame in static:
                frame = static[frame]
                continue
            before = [p for s, p in edges.get(frame, []) if s <= stamp]
            if not before:
                return False
            frame = before[-1]
        return True

    by_frame = Counter()
    unplaced = Counter()
    for topic, frame, stamp in stamped:
        if frame == "" and topic == "/rosout":
            continue
        by_frame[frame] += 1
        if not reaches_world(frame, stamp):
            unplaced[(topic, frame)] += 1
    for (topic, frame), n in sorted(unplaced.items()):
        failures.append(f"{topic}: {n} messages in frame {frame!r} have no transform to 'world' at their stamp")
    for need in ("/tf", "/tf_static"):
        if counts[need] == 0:
            failures.append(f"no messages on {need}")
    print(f"rosbags decoded {sum(counts.values())} messages on {len(counts)} topics")
    print("frames: " + ", ".join(f"{f or '(empty)'} {n}" for f, n in sorted(by_frame.items())))
    for f in failures:
        print(f"{path}: {f}")
    print(f"check_tf: {len(stamped)} headers placed, {len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
