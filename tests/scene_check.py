#!/usr/bin/env python3
"""scene_check.py -- sonar-sim's walls echo causally: a return starts at the nearest wall inside the 2-degree beam.

Usage: scene_check.py SCENE.csv SCENE.json. For every beam direction of a still sonar whose beam
meets a wall in range, away from the scene's objects, the level averaged over the sweeps (speckle
averages out) must first rise above the noise at the sample where the nearest wall point inside
+-1 degree lies, to one sample. Exits 1 naming the first direction that does not.
"""
import csv
import json
import math
import sys

from sim_geom import ray_segment


def cone_near(th, hw, walls):
    """The nearest wall point within the cone th +- hw (radians), by fine rays."""
    best = None
    for i in range(201):
        a = th - hw + 2 * hw * i / 200
        for w in walls:
            t = ray_segment(math.cos(a), math.sin(a), *w)
            if t is not None and (best is None or t < best):
                best = t
    return best


def main():
    rows, truth = sys.argv[1], json.load(open(sys.argv[2]))
    rng, n, walls = truth["range_m"], truth["samples"], truth["walls"]
    objs = {(round(o["x"], 1), round(o["y"], 1)) for s in truth["sweeps"] for o in s["objects"] + s["hidden"]}
    sums, counts = {}, {}
    with open(rows) as f:
        for r in csv.reader(f):
            a, v = int(r[2]), [int(x) for x in r[3].split()]
            s = sums.setdefault(a, [0] * len(v))
            for i, x in enumerate(v):
                s[i] += x
            counts[a] = counts.get(a, 0) + 1
    cell, checked = rng / n, 0
    for a in sorted(sums):
        th = a * math.pi / 200
        if any(abs(math.remainder(th - math.atan2(y, x), 2 * math.pi)) < math.radians(15) for x, y in objs):
            continue
        near = cone_near(th, math.radians(1.0), walls)
        if near is None or near > rng - 0.5:
            continue
        mean = [x / counts[a] for x in sums[a]]
        i0 = int(1.0 / cell) + 40  # past the ring-down
        # the first sample standing 30 levels above the median of the 40 before it (the noise falls with range)
        got = next((i for i in range(i0, n) if mean[i] > sorted(mean[i - 40:i])[20] + 30), None)
        want = math.ceil(near / cell - 0.5)  # the first sample whose centre lies at or past the wall
        checked += 1
        if got is None or abs(got - want) > 1:
            print(f"scene_check: angle {a} gradians: the return starts at sample {got}, the nearest wall in the "
                  f"beam at {near:.3f} m is sample {want}")
            return 1
    print(f"scene_check: {checked} directions, each wall's return starts at the nearest wall inside the beam (+-1 sample)")
    return 0 if checked > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
