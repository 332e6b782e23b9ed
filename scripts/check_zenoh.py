#!/usr/bin/env python3
"""A third-party Zenoh peer (Python `eclipse-zenoh`) watching a run that `harvey run
--zenoh-connect` exports: it listens on a loopback endpoint, subscribes to `harvey/**`, runs the
command given after `--`, and checks that every message the run recorded (run.mcap, read with
the `mcap` package) arrived on Zenoh under its topic's key, with the same CDR bytes, and the
sequence number and stamp in Harvey's attachment (docs/zenoh.md).

usage: check_zenoh.py PORT RUN_MCAP -- COMMAND...
"""

import struct
import sys

from zenoh_peer import watch


def main() -> int:
    if len(sys.argv) < 5 or sys.argv[3] != "--":
        print(__doc__, file=sys.stderr)
        return 2
    port, mcap_path, command = int(sys.argv[1]), sys.argv[2], sys.argv[4:]
    watched = watch(port, "harvey/**", command, mcap_path)
    if watched is None:
        return 1
    got, _, recorded, _ = watched
    expected = {"harvey" + topic: messages for topic, messages in recorded.items()}
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
