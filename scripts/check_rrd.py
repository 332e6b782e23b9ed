#!/usr/bin/env python3
"""Checks a Harvey Rerun recording with Rerun 0.36.3's own reader (rerun-sdk).

usage: check_rrd.py RUN.rrd [--same-as OTHER.rrd] [--need ENTITY]... [--say ENTITY=TEXT]...

- every entity the view is built on is there (the camera image, the world view round the robot
  and the whole world, the paths, one plot subtree per quantity, the log and the state lanes),
  and each --need entity too;
- the log is a log, not a per-tick stream: over 100 ticks or more, its lines are fewer than half
  the true poses, and no one line (its numbers aside) recurs on a twentieth of the ticks or more
  (a warning raised each frame; an eventful mission may log often, but not the same thing);
- each --say: a line of the log entity ENTITY contains TEXT, at level WARN or ERROR (a service's
  own warning brought in from `rosout`);
- with --same-as, both files draw the same entities, but for the loop latency (wall clock, drawn
  only by the live recorder): `harvey export` draws what the recorder drew live.
"""
import argparse
import re
import sys
from collections import Counter

import rerun as rr

ALWAYS = [
    "/camera/image", "/world/map/walls", "/world/near/walls", "/world/near/frame", "/world/paths/truth",
    "/world/paths/estimated", "/world/robot/truth", "/world/near/uncertainty", "/world/map/uncertainty", "/plots/uncertainty/area_m2",
    "/plots/heading/wedge_deg", "/log/executive", "/states/mission", "/states/ums",
]
LIVE_ONLY = {"/plots/latency/loop_ms"}


def rows(path):
    """Rows per entity path in the recording (not the blueprint)."""
    counts = Counter()
    for chunk in rr.experimental.RrdReader(path).stream().to_chunks():
        counts[str(chunk.entity_path)] += chunk.num_rows
    return counts


def log_lines(path):
    """(entity, level, text) of every line of the log."""
    out = []
    for chunk in rr.experimental.RrdReader(path).stream().to_chunks():
        entity = str(chunk.entity_path)
        if not entity.startswith("/log/"):
            continue
        batch = chunk.to_record_batch()
        if "TextLog:text" not in batch.schema.names or "TextLog:level" not in batch.schema.names:
            continue
        texts = batch.column("TextLog:text").to_pylist()
        levels = batch.column("TextLog:level").to_pylist()
        for text, level in zip(texts, levels):
            for t, l in zip(text or [], level or []):
                out.append((entity, l, t))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("rrd")
    ap.add_argument("--same-as")
    ap.add_argument("--need", action="append", default=[])
    ap.add_argument("--say", action="append", default=[])
    a = ap.parse_args()
    counts = rows(a.rrd)
    problems = [f"{a.rrd}: no entity {e}" for e in ALWAYS + a.need if counts[e] == 0]
    lines = log_lines(a.rrd)
    truths = counts["/world/robot/truth"]
    if truths >= 100 and len(lines) * 2 >= truths:
        problems.append(f"{a.rrd}: {len(lines)} log lines for {truths} true poses: the log repeats per tick")
    alike = Counter((e, re.sub(r"[0-9.]+", "#", t)) for e, _, t in lines)
    for (e, t), n in alike.most_common(1):
        if truths >= 100 and n * 20 >= truths:
            problems.append(f"{a.rrd}: {e} says {t!r} {n} times in {truths} ticks: a warning raised per tick")
    said = [(e, l, t) for e, l, t in lines if l in ("WARN", "ERROR")]
    for want in a.say:
        entity, _, text = want.partition("=")
        if not any(e == entity and text in t for e, _, t in said):
            problems.append(f"{a.rrd}: no WARN or ERROR line of {entity} says {text!r}")
    if a.same_as:
        other = rows(a.same_as)
        mine = {e for e in counts if not e.startswith("/__")} - LIVE_ONLY
        theirs = {e for e in other if not e.startswith("/__")} - LIVE_ONLY
        for e in sorted(mine ^ theirs):
            where = a.rrd if e in mine else a.same_as
            problems.append(f"{e} is drawn only in {where}")
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        sys.exit(1)
    print(f"{a.rrd}: {len(counts)} entities, {len(lines)} log lines for {truths} true poses"
          + (f", the same entities as {a.same_as}" if a.same_as else ""))


if __name__ == "__main__":
    main()
