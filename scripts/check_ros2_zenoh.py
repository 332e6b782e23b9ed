#!/usr/bin/env python3
"""What a ROS 2 Jazzy node on rmw_zenoh would see of a run exported with `--ros2-domain`, checked
without ROS 2: a third-party Zenoh peer (Python `eclipse-zenoh`) listens on loopback, subscribes to
the domain's keys (`<domain>/<topic>/<pkg>::msg::dds_::<Type>_/RIHS01_<hash>`) and to the
liveliness tokens under `@ros2_lv/<domain>`, runs the command given after `--`, then checks with
`rosbags` (its type system the oracle for the hashes) that:
- every recorded topic came on exactly one key, whose type and RIHS01 hash are those rosbags
  computes from the topic's schema in run.mcap;
- every recorded message came, its payload byte for byte, and decodes with rosbags' CDR decoder;
- the attachment is rmw_zenoh's: sequence numbers 1, 2, ... per publisher, the source timestamp
  equal to the recorded log time, then a 16-byte GID;
- a node token (`NN`) and, per key, a publisher token (`MP`) with the same type and hash.

usage: check_ros2_zenoh.py PORT DOMAIN RUN_MCAP -- COMMAND...
"""

import struct
import sys

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from zenoh_peer import watch


def main() -> int:
    if len(sys.argv) < 6 or sys.argv[4] != "--":
        print(__doc__, file=sys.stderr)
        return 2
    port, domain, mcap_path, command = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[5:]
    watched = watch(port, f"{domain}/**", command, mcap_path, liveliness=f"@ros2_lv/{domain}/**")
    if watched is None:
        return 1
    got, tokens, expected, schemas = watched
    problems, decoded = [], 0
    by_topic = {}
    for key in got:
        parts = key.split("/")
        by_topic.setdefault("/" + "/".join(parts[1:-2]), []).append((key, parts[-2], parts[-1]))
    for topic, messages in sorted(expected.items()):
        keys = by_topic.get(topic, [])
        if len(keys) != 1:
            problems.append(f"{topic}: {len(keys)} keys ({keys})")
            continue
        key, dds_type, rihs = keys[0]
        name, text = schemas[topic]
        store = get_typestore(Stores.EMPTY)
        store.register(get_types_from_msg(text, name))
        pkg, _, typ = name.split("/")
        if dds_type != f"{pkg}::msg::dds_::{typ}_":
            problems.append(f"{topic}: type {dds_type} for {name}")
        if rihs != store.hash_rihs01(name):
            problems.append(f"{topic}: {rihs}, rosbags computes {store.hash_rihs01(name)}")
        samples = got[key]
        if len(samples) != len(messages):
            problems.append(f"{topic}: {len(samples)} samples for {len(messages)} recorded messages")
            continue
        for i, ((att, payload), m) in enumerate(zip(samples, messages)):
            seq, stamp = struct.unpack_from("<qq", att, 0) if len(att) == 33 else (None, None)
            if len(att) != 33 or att[16] != 16 or seq != i + 1 or stamp != m.log_time:
                problems.append(f"{topic} #{i}: attachment {att.hex()} (seq {seq}, stamp {stamp} vs {m.log_time})")
                break
            if payload != m.data:
                problems.append(f"{topic} #{i}: payload differs from the recording's")
                break
            store.deserialize_cdr(payload, name)
            decoded += 1
        if not any(f"/{topic.replace('/', '%')}/{dds_type}/{rihs}/" in t for t in tokens):
            problems.append(f"{topic}: no publisher token with {dds_type}/{rihs} among {len(tokens)}")
    if not any("/NN/" in t for t in tokens):
        problems.append("no node token (NN)")
    if problems:
        print("check_ros2_zenoh: FAILED\n  " + "\n  ".join(problems), file=sys.stderr)
        return 1
    print(f"check_ros2_zenoh: {len(expected)} topics on rmw_zenoh keys, RIHS01 hashes as rosbags computes "
          f"them, {decoded} messages byte for byte and decoded by rosbags, {len(tokens)} liveliness tokens")
    return 0


if __name__ == "__main__":
    sys.exit(main())
