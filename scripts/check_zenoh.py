#!/usr/bin/env python3
"""A third-party Zenoh peer (Python `eclipse-zenoh`) watching a run that `harvey run
--zenoh-connect` exports: it listens on a loopback endpoint, subscribes to `harvey/**`, runs the
command given after `--`, and checks that every message the run recorded (run.mcap, read with
the `mcap` package) arrived on Zenoh under its topic's key, with the same CDR bytes, and the
sequence number and stamp in Harvey's attachment (docs/zenoh.md).

usage: check_zenoh.py PORT RUN_MCAP -- COMMAND...
"""

import struct
import subprocess
import sys
import threading
import time

import zenoh
from mcap.reader import make_reader

DERIVED = ("/tf", "/tf_static", "/markers/", "/camera/camera_info")


def main() -> int:
    if len(sys.argv) < 5 or sys.argv[3] != "--":
        print(__doc__, file=sys.stderr)
        return 2
    port, mcap_path, command = int(sys.argv[1]), sys.argv[2], sys.argv[4:]
    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("listen/endpoints", f'["tcp/127.0.0.1:{port}"]')
    conf.insert_json5("scouting/multicast/enabled", "false")
    conf.insert_json5("scouting/gossip/enabled", "false")
    got = {}
    lock = threading.Lock()

    def on_sample(sample):
        att = sample.attachment.to_bytes() if sample.attachment is not None else b""
        key = str(sample.key_expr)
        with lock:
            got.setdefault(key, []).append((att, sample.payload.to_bytes()))

    with zenoh.open(conf) as session:
        sub = session.declare_subscriber("harvey/**", on_sample)
        run = subprocess.run(command)
        if run.returncode != 0:
            print(f"check_zenoh: the run failed ({run.returncode})", file=sys.stderr)
            return 1
        expected = {}
        with open(mcap_path, "rb") as f:
            for _schema, channel, message in make_reader(f).iter_messages():
                if channel.topic.startswith(DERIVED):
                    continue
                expected.setdefault("harvey" + channel.topic, []).append(message)
        want = sum(len(v) for v in expected.values())
        # The bridge has put everything before the run ended; what is in flight arrives soon.
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            with lock:
                if sum(len(v) for v in got.values()) >= want:
                    break
            time.sleep(0.1)
        sub.undeclare()
    problems = []
    for key, messages in sorted(expected.items()):
        samples = got.get(key, [])
        if len(samples) != len(messages):
            problems.append(f"{key}: {len(samples)} samples for {len(messages)} recorded messages")
            continue
        for i, ((att, payload), m) in enumerate(zip(samples, messages)):
            if att[:4] != b"HVZ\x01" or len(att) != 24:
                problems.append(f"{key} #{i}: attachment {att[:8]!r}... is not Harvey's v1")
                break
            seq, stamp = struct.unpack_from("<QQ", att, 4)
            if payload != m.data or stamp != m.log_time or seq % 2**32 != m.sequence:
                problems.append(f"{key} #{i}: seq {seq} stamp {stamp} differs from the recording's "
                                f"({m.sequence}, {m.log_time}, same bytes: {payload == m.data})")
                break
    extra = sorted(set(got) - set(expected))
    if extra:
        problems.append(f"keys not in the recording: {extra}")
    total = sum(len(v) for v in got.values())
    if problems:
        print("check_zenoh: FAILED\n  " + "\n  ".join(problems), file=sys.stderr)
        return 1
    print(f"check_zenoh: {total} samples on {len(got)} keys, every recorded message, byte for byte")
    return 0


if __name__ == "__main__":
    sys.exit(main())
