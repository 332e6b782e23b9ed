"""What the Zenoh check scripts share: a Python `eclipse-zenoh` peer listening on loopback with
scouting off that collects the samples under a key expression while a command runs, and the
recorded (non-derived) messages of a run.mcap to compare them with."""

import subprocess
import sys
import threading
import time

import zenoh
from mcap.reader import make_reader

DERIVED = ("/tf", "/tf_static", "/markers/", "/camera/camera_info")


def peer_config(port: int) -> "zenoh.Config":
    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("listen/endpoints", f'["tcp/127.0.0.1:{port}"]')
    conf.insert_json5("scouting/multicast/enabled", "false")
    conf.insert_json5("scouting/gossip/enabled", "false")
    return conf


def recorded(mcap_path: str):
    """The recorded messages by topic (`/odometry`) and each topic's (schema name, text)."""
    expected, schemas = {}, {}
    with open(mcap_path, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            if channel.topic.startswith(DERIVED):
                continue
            expected.setdefault(channel.topic, []).append(message)
            schemas[channel.topic] = (schema.name, schema.data.decode())
    return expected, schemas


def watch(port: int, key_expr: str, command, mcap_path: str, liveliness: str = ""):
    """Runs `command` while collecting the samples under `key_expr` (key -> [(attachment,
    payload)]) and, if given, the liveliness tokens under `liveliness`; then waits (at most
    30 s) until as many samples came as run.mcap recorded. None if the run failed."""
    got, tokens, lock = {}, set(), threading.Lock()

    def on_sample(sample):
        att = sample.attachment.to_bytes() if sample.attachment is not None else b""
        with lock:
            got.setdefault(str(sample.key_expr), []).append((att, sample.payload.to_bytes()))

    def on_token(sample):
        with lock:
            tokens.add(str(sample.key_expr))

    with zenoh.open(peer_config(port)) as session:
        sub = session.declare_subscriber(key_expr, on_sample)
        live = session.liveliness().declare_subscriber(liveliness, on_token, history=True) if liveliness else None
        run = subprocess.run(command)
        if run.returncode != 0:
            print(f"the run failed ({run.returncode})", file=sys.stderr)
            return None
        expected, schemas = recorded(mcap_path)
        want = sum(len(v) for v in expected.values())
        # The bridge has put everything before the run ended; what is in flight arrives soon.
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            with lock:
                if sum(len(v) for v in got.values()) >= want:
                    break
            time.sleep(0.1)
        sub.undeclare()
        if live is not None:
            live.undeclare()
    return got, tokens, expected, schemas
