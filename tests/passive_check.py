#!/usr/bin/env python3
"""passive_check.py -- sonard --passive's sweeps against `sonard --replay` of the beams the driving program recorded:
every sweep the recording holds whole (all but its last, which the driver may have left open) must have the same
beams and the same detections (position, area, points, hull; times aside: each program timed the beams by its own
receipt). Usage: passive_check.py REPLAY.jsonl PASSIVE.jsonl. Prints one line; exits 1 when they differ."""
import json
import sys


def sweeps(path):
    return [json.loads(line) for line in open(path) if line.startswith("{")]


def shape(s):
    return (s["beams"], [(d["x_m"], d["y_m"], d["area_m2"], d["points"], d["hull"], d.get("kind")) for d in s["detections"]])


r, p = sweeps(sys.argv[1]), sweeps(sys.argv[2])
n = len(r) - 1
bad = [i for i in range(n) if i >= len(p) or shape(r[i]) != shape(p[i])]
dets = sum(len(s["detections"]) for s in r[:n])
print(f"{n} whole sweeps of the recording, {dets} detections: {'equal' if not bad else 'differ at sweeps %s' % bad[:5]} "
      f"(passive {len(p)} sweeps, replay {len(r)})")
sys.exit(1 if bad or n < 1 else 0)
