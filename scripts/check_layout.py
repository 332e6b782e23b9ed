"""Checks that the Foxglove layout in the repository (docs/foxglove-layout.json) shows what a
recording has: every topic a panel names is in the recording, the image panel's topic is a
`sensor_msgs/msg/Image`, the log panel's a `rcl_interfaces/msg/Log`, the 3D panel follows a frame
the recording's transforms name, and every plot path resolves to a number in decoded messages
(mcap-ros2-support, the recording's own schemas).

Usage: check_layout.py LAYOUT.json RUN.MCAP
"""
import json
import sys

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory


def main() -> int:
    layout_path, mcap_path = sys.argv[1], sys.argv[2]
    with open(layout_path) as f:
        layout = json.load(f)
    first = {}  # topic -> (schema name, first decoded message)
    frames = set()
    with open(mcap_path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, _, decoded in reader.iter_decoded_messages(log_time_order=False):
            first.setdefault(channel.topic, (schema.name, decoded))
            if channel.topic in ("/tf", "/tf_static"):
                for t in decoded.transforms:
                    frames.update((t.header.frame_id, t.child_frame_id))
    failures, checked = [], 0

    def need(topic, schema=None, panel=""):
        nonlocal checked
        checked += 1
        if topic not in first:
            failures.append(f"{panel}: topic {topic} is not in the recording")
        elif schema and first[topic][0] != schema:
            failures.append(f"{panel}: {topic} is {first[topic][0]}, not {schema}")

    for panel, config in layout["configById"].items():
        kind = panel.split("!")[0]
        for topic in config.get("topics", {}):
            need(topic, panel=panel)
        if image := config.get("imageMode", {}).get("imageTopic"):
            need(image, "sensor_msgs/msg/Image", panel)
        if calibration := config.get("imageMode", {}).get("calibrationTopic"):
            need(calibration, "sensor_msgs/msg/CameraInfo", panel)
        if kind == "RosOut":
            need(config["topicToRender"], "rcl_interfaces/msg/Log", panel)
        if follow := config.get("followTf"):
            checked += 1
            if follow not in frames:
                failures.append(f"{panel}: follows frame {follow!r}, which no transform names ({sorted(frames)})")
        for p in config.get("paths", []):
            value = p["value"]
            topic = max((t for t in first if value.startswith(t + ".")), key=len, default=None)
            if topic is None:
                failures.append(f"{panel}: plot path {value} names no recorded topic")
                continue
            checked += 1
            v = first[topic][1]
            for field in value[len(topic) + 1 :].split("."):
                v = getattr(v, field, None)
            if not isinstance(v, (int, float)) or isinstance(v, bool):
                failures.append(f"{panel}: plot path {value} is not a number ({v!r})")
    for f in failures:
        print(f"{layout_path}: {f}")
    print(f"check_layout: {checked} references checked, {len(failures)} failures")
    return 1 if failures or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
