"""`python -m harvey_client`: print a running domain's messages, the topic table, and compare
this package's layouts with Rust's.

    python -m harvey_client echo harvey_ sonar/ring --count 5
    python -m harvey_client echo harvey_ camera/frame --count 1 --json --save-frames /tmp/f
    python -m harvey_client topics
    python -m harvey_client check-layout rust-layouts.json
"""

import argparse
import hashlib
import json
import math
import os
import sys
from typing import Any, Dict, List, Optional

from . import msgs
from .client import DEFAULT_PREFIX, PREFIX_ENV, Frame, HarveyError, Subscription
from .topics import ALL


def _finite(value: Any) -> Any:
    """JSON has no NaN or infinities: they are written as the strings "NaN", "inf", "-inf"."""
    if isinstance(value, float) and not math.isfinite(value):
        return "NaN" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value


def _record(topic: str, msg: Any, save_frames: Optional[str]) -> Dict[str, Any]:
    if isinstance(msg, Frame):
        pixels = msg.pixels.tobytes()
        out: Dict[str, Any] = {
            "topic": topic,
            "type": msgs.FrameHeader.type_name(),
            "header": msg.header.to_dict(),
            "encoding": msg.header.encoding_name,
            "shape": list(msg.pixels.shape),
            "sha256": hashlib.sha256(pixels).hexdigest(),
        }
        if save_frames:
            os.makedirs(save_frames, exist_ok=True)
            path = os.path.join(save_frames, f"frame-{msg.stamp_ns}.raw")
            with open(path, "wb") as f:
                f.write(pixels)
            out["file"] = os.path.abspath(path)
        return out
    return {"topic": topic, "type": msg.type_name(), "msg": _finite(msg.to_dict())}


def echo(args: argparse.Namespace) -> int:
    count = args.count
    n = 0
    try:
        with Subscription(args.prefix, args.topic, wait_s=args.wait_s) as sub:
            for msg in sub.messages(count=count, timeout_s=args.timeout_s):
                n += 1
                rec = _record(sub.topic.name, msg, args.save_frames)
                if args.json:
                    print(json.dumps(rec), flush=True)
                else:
                    body = rec.get("msg") or {k: v for k, v in rec.items() if k not in ("topic", "type")}
                    print(f"--- {rec['topic']} ({rec['type']})\n{body}", flush=True)
    except HarveyError as e:
        print(f"harvey_client: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    if count is not None and n < count:
        print(
            f"harvey_client: {n} of {count} messages of `{args.topic}` within {args.timeout_s} s",
            file=sys.stderr,
        )
        return 1
    return 0


def topic_table() -> List[Dict[str, Any]]:
    out = []
    for name, t in ALL.items():
        out.append(
            {
                "name": name,
                "type_name": t.payload.type_name(),
                "frames": t.frames,
                "qos": {
                    "buffer": t.qos.buffer,
                    "borrowed": t.qos.borrowed,
                    "history": t.qos.history,
                    "max_publishers": t.qos.max_publishers,
                    "max_subscribers": t.qos.max_subscribers,
                },
            }
        )
    return out


def check_layout(args: argparse.Namespace) -> int:
    """Compares this package's types and topic table with what the Rust side printed:
    `{"types": [...], "topics": [...]}` (see `tests/python_client/`)."""
    with open(args.file) as f:
        rust = json.load(f)
    problems: List[str] = []
    ours = {t["name"]: t for t in msgs.layouts()}
    theirs = {t["name"]: t for t in rust["types"]}
    for name in sorted(set(ours) ^ set(theirs)):
        side = "Rust" if name in theirs else "Python"
        problems.append(f"type {name} is only on the {side} side")
    for name in sorted(set(ours) & set(theirs)):
        a, b = ours[name], theirs[name]
        for key in ("type_name", "size", "align"):
            if a[key] != b[key]:
                problems.append(f"{name}.{key}: Python {a[key]!r}, Rust {b[key]!r}")
        if a["fields"] != b["fields"]:
            problems.append(f"{name} fields: Python {a['fields']}, Rust {b['fields']}")
    table = {t["name"]: t for t in topic_table()}
    rust_topics = {t["name"]: t for t in rust["topics"]}
    if list(table) != [t["name"] for t in rust["topics"]]:
        problems.append(f"topic table: Python {list(table)}, Rust {list(rust_topics)}")
    for name in sorted(set(table) & set(rust_topics)):
        if table[name] != rust_topics[name]:
            problems.append(f"topic {name}: Python {table[name]}, Rust {rust_topics[name]}")
    for p in problems:
        print(f"mismatch: {p}")
    fields = sum(len(t["fields"]) for t in ours.values())
    print(
        f"layout: {len(ours)} types, {fields} fields, {len(table)} topics compared, "
        f"{len(problems)} mismatches"
    )
    return 1 if problems else 0


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m harvey_client", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)

    e = sub.add_parser("echo", help="print a topic's messages")
    e.add_argument("prefix", nargs="?", default=os.environ.get(PREFIX_ENV, DEFAULT_PREFIX),
                   help=f"the domain's prefix (default: ${PREFIX_ENV} or {DEFAULT_PREFIX})")
    e.add_argument("topic", help="a topic name, e.g. sonar/ring, odometry, camera/frame")
    e.add_argument("--count", type=int, help="stop after this many messages")
    e.add_argument("--timeout-s", type=float, help="stop after this many seconds")
    e.add_argument("--wait-s", type=float, default=0.0,
                   help="wait this long for the domain and topic to appear")
    e.add_argument("--json", action="store_true", help="one JSON object a line")
    e.add_argument("--save-frames", metavar="DIR",
                   help="write each frame's pixels to DIR/frame-<stamp_ns>.raw")
    sub.add_parser("topics", help="print the topic table as JSON lines")
    sub.add_parser("layout", help="print this package's type layouts as JSON")
    c = sub.add_parser("check-layout", help="compare the layouts with Rust's (JSON file)")
    c.add_argument("file")

    args = parser.parse_args(argv)
    if args.command == "echo":
        return echo(args)
    if args.command == "topics":
        for t in topic_table():
            print(json.dumps(t))
        return 0
    if args.command == "layout":
        print(json.dumps({"types": msgs.layouts(), "topics": topic_table()}, indent=1))
        return 0
    return check_layout(args)


if __name__ == "__main__":
    sys.exit(main())
