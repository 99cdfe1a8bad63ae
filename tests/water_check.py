#!/usr/bin/env python3
"""water_check.py -- sonar-sim --water draws the scene's people into the recording and changes nothing else.

Usage: water_check.py WATER.csv HYBRID.csv HYBRID.json. The hybrid must keep every row's time and angle and
the truth's sweep count must be sonard's (its --json output in --sweeps-from, optional); every sample that
differs from the water's must lie at the range of an object where the truth places it then (between its marks, seen or hidden),
through its depth, within 12.5 degrees of its edge's bearing; and each object must have changed samples within 1 m of it in
80 % of its sweeps seen.
Exits 1 naming the first row or object that breaks this.
"""
import argparse
import json
import math
import sys


def rows(path):
    out = []
    for line in open(path):
        p = line.rstrip("\n").split(",")
        if len(p) < 4 or not p[0].isdigit():
            continue
        out.append((int(p[0]), int(p[1]), int(p[2]), [int(x) for x in p[3].strip('"').split()]))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("water")
    ap.add_argument("hybrid")
    ap.add_argument("truth")
    ap.add_argument("--sweeps-from", help="sonard --json output of the hybrid: its sweeps must be the truth's")
    a = ap.parse_args()
    water, hybrid, truth = rows(a.water), rows(a.hybrid), json.load(open(a.truth))
    if len(water) != len(hybrid):
        sys.exit(f"water_check: {len(water)} rows of water, {len(hybrid)} in the hybrid")
    sweeps = truth["sweeps"]
    if a.sweeps_from:
        n = sum(1 for _ in open(a.sweeps_from))
        if n != len(sweeps):
            sys.exit(f"water_check: the truth has {len(sweeps)} sweeps, sonard cut {n}")
    rng = truth["range_m"]
    # Where the truth puts each object and when (the beam nearest its bearing); the rows nearest that time draw it.
    marks = [(o["t_us"], o["x"], o["y"], o.get("radius", 0.35), s["sweep"], o["id"], vis, math.hypot(o.get("vx", 0.0), o.get("vy", 0.0)))
             for s in sweeps for vis, key in ((1, "objects"), (0, "hidden")) for o in s[key]]
    drawn = set()
    track = {}
    for m in sorted(marks):
        track.setdefault(m[5], []).append(m)

    def where(ms, t):
        """The object's (x, y, radius, sweep) at t: between its marks, linearly; within 4 s of its first or last."""
        if t < ms[0][0] - 4000000 or t > ms[-1][0] + 4000000:
            return None
        for a, b in zip(ms, ms[1:]):
            if a[0] <= t <= b[0] and b[0] - a[0] <= 20000000:
                # Between marks it may have turned: its radius grows by how far it could go from the nearer one.
                f = (t - a[0]) / max(1, b[0] - a[0])
                slack = max(a[7], b[7]) * min(t - a[0], b[0] - t) * 1e-6
                return a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]), a[3] + slack, (a if f < 0.5 else b)[4], a[5]
        m = min(ms, key=lambda m: abs(m[0] - t))
        return (m[1], m[2], m[3] + m[7] * abs(m[0] - t) * 1e-6, m[4], m[5]) if abs(m[0] - t) <= 4000000 else None

    for i, (w, h) in enumerate(zip(water, hybrid)):
        if w[:3] != h[:3]:
            sys.exit(f"water_check: row {i + 1}: time or angle changed ({w[:3]} -> {h[:3]})")
        t_us = w[0] * 1000000 + w[1] // 1000
        near = [p for p in (where(ms, t_us) for ms in track.values()) if p is not None]
        th = w[2] * math.pi / 200.0
        n = len(w[3])
        for k, (x, y) in enumerate(zip(w[3], h[3])):
            if x == y:
                continue
            r = (k + 0.5) * rng / n
            px, py = r * math.cos(th), r * math.sin(th)
            # An echo lies at the object's range, through its depth, and spreads across beams (the Ping360's
            # 2-degree beam through its intensity scale: a person's echo spans about 10 degrees beyond its own width; its
            # tail, 12 degrees each side of it).
            ok = [m for m in near if abs(r - math.hypot(m[0], m[1])) <= m[2] + 0.3 and
                  abs(math.remainder(th - math.atan2(m[1], m[0]), 2 * math.pi)) <=
                  math.asin(min(1.0, m[2] / max(m[2], math.hypot(m[0], m[1])))) + math.radians(12.5)]
            if not ok:
                sys.exit(f"water_check: row {i + 1} (angle {w[2]}), sample {k} ({r:.2f} m): changed {x} -> {y}, "
                         "away from any object there then")
            drawn.update((m[3], m[4]) for m in ok if math.hypot(px - m[0], py - m[1]) <= 1.0)
    objs = {}
    for m in marks:
        if m[6]:
            objs.setdefault(m[5], []).append(m[4])
    for oid, sw in sorted(objs.items()):
        got = sum(1 for s in sw if (s, oid) in drawn)
        if got < 0.8 * len(sw):
            sys.exit(f"water_check: object {oid} was drawn in {got} of its {len(sw)} sweeps")
    print(f"water_check: {len(hybrid)} rows, {len(sweeps)} sweeps; {len(objs)} objects drawn, nothing else changed")


if __name__ == "__main__":
    main()
