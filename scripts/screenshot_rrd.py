#!/usr/bin/env python3
"""Renders a Rerun (.rrd) recording to a PNG with Rerun 0.36.3's own viewer, headless.

usage: screenshot_rrd.py IN.rrd OUT.png [--size 1600x1000] [--timeline sim_time] [--time max|min|N]

`rerun IN.rrd --screenshot-to OUT.png` takes its picture a fixed ten frames after start-up,
before a large file has loaded, with the time cursor wherever playback has got to. So this starts
`rerun --headless` (software Vulkan, no X server) and steers it through `rerun viewer-mcp` (the
viewer's JSON-RPC control channel on stdin/stdout): it waits until the recording's timeline
ranges stop growing (the file is loaded), pauses the time cursor at the end (or --time), and
asks the viewer for its screenshot.
"""
import argparse
import json
import os
import signal
import socket
import subprocess
import sys
import time


class Control:
    """One `rerun viewer-mcp` session."""

    def __init__(self, rerun, env):
        self.proc = subprocess.Popen([rerun, "viewer-mcp"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, env=env, text=True, bufsize=1)
        self.next_id = 0
        self.request("initialize", {"protocolVersion": "2024-11-05", "capabilities": {},
                                    "clientInfo": {"name": "harvey-screenshots", "version": "1"}})
        self.send({"jsonrpc": "2.0", "method": "notifications/initialized"})

    def send(self, msg):
        self.proc.stdin.write(json.dumps(msg) + "\n")
        self.proc.stdin.flush()

    def request(self, method, params):
        self.next_id += 1
        self.send({"jsonrpc": "2.0", "id": self.next_id, "method": method, "params": params})
        for line in self.proc.stdout:
            msg = json.loads(line)
            if msg.get("id") == self.next_id:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg["result"]
        raise RuntimeError("rerun viewer-mcp exited")

    def tool(self, name, **arguments):
        result = self.request("tools/call", {"name": name, "arguments": arguments})
        if result.get("isError"):
            raise RuntimeError(f"{name}: {json.dumps(result)[:500]}")
        if "structuredContent" in result:
            return result["structuredContent"]
        text = "".join(c.get("text", "") for c in result.get("content", []) if c.get("type") == "text")
        try:
            return json.loads(text)
        except ValueError:
            return text

    def close(self):
        try:
            self.proc.stdin.close()
            self.proc.wait(10)
        except (OSError, subprocess.TimeoutExpired):
            self.proc.kill()


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def connect(rerun, env, port, viewer, deadline):
    """A control session connected to the viewer, once it listens."""
    while True:
        control = None
        try:
            control = Control(rerun, env)
            control.tool("connect", endpoint=f"http://127.0.0.1:{port}")
            return control
        except RuntimeError:
            if control:
                control.close()
            if time.time() > deadline or viewer.poll() is not None:
                raise
            time.sleep(0.5)


def loaded(control, deadline, settle_s):
    """The active recording's state once its timelines have not grown for `settle_s`."""
    last, since = None, time.time()
    while True:
        state = control.tool("viewer_state")
        recs = [r for r in state.get("recordings", []) if r["store_id"] == state.get("active_store_id")]
        key = json.dumps(recs[0]["timelines"], sort_keys=True) if recs else None
        if key != last:
            last, since = key, time.time()
        elif key and time.time() - since >= settle_s:
            return recs[0]
        if time.time() > deadline:
            raise RuntimeError(f"the recording did not load in time: {json.dumps(state)[:400]}")
        time.sleep(0.2)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("rrd")
    ap.add_argument("out")
    ap.add_argument("--size", default="1600x1000", help="window size in logical points")
    ap.add_argument("--timeline", default="sim_time")
    ap.add_argument("--time", default="max", help="max, min, or a time on the timeline (ns or sequence)")
    ap.add_argument("--settle", type=float, default=1.5, help="seconds the timelines must stay unchanged")
    ap.add_argument("--timeout", type=float, default=300)
    ap.add_argument("--rerun", default="rerun")
    a = ap.parse_args()
    if not os.path.isfile(a.rrd):
        sys.exit(f"screenshot_rrd: no such recording: {a.rrd}")
    # RUST_LOG=error keeps the viewer's info and warning toasts out of the picture.
    env = dict(os.environ, RERUN_ANALYTICS="0", RUST_LOG=os.environ.get("RUST_LOG", "error"))
    port = free_port()
    started = time.time()
    deadline = started + a.timeout
    # Its own process group: the venv's `rerun` is a wrapper round the real binary.
    viewer = subprocess.Popen([a.rerun, "--headless", os.path.abspath(a.rrd), "--window-size", a.size,
                               "--port", str(port), "--hide-welcome-screen"], env=env,
                              stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                              start_new_session=True)
    control = None
    try:
        control = connect(a.rerun, env, port, viewer, deadline)
        rec = loaded(control, deadline, a.settle)
        timelines = {t["timeline"]: t for t in rec["timelines"]}
        if a.timeline not in timelines:
            raise RuntimeError(f"{a.rrd} has no timeline {a.timeline!r} (it has {sorted(timelines)})")
        tl = timelines[a.timeline]
        at = tl["max"] if a.time == "max" else tl["min"] if a.time == "min" else int(a.time)
        control.tool("set_time", timeline=a.timeline, time=at, play=False)
        time.sleep(1.0)  # a few frames drawn at the new time
        control.tool("screenshot", pixels_per_point=1.0, save_path=os.path.abspath(a.out))
        print(f"{a.out}: {a.rrd} at {a.timeline} {at} in {time.time() - started:.1f} s", file=sys.stderr)
    finally:
        if control:
            control.close()
        try:
            os.killpg(viewer.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        viewer.wait(10)


if __name__ == "__main__":
    main()
