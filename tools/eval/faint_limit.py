"""faint_limit.py -- how well faint targets can stand out against a survey at all: an idealised detector on the raw beams.

Each cell's level and spread come from an empty recording of the site (the survey's statistics, plain mean and
standard deviation); each sweep of the occupied recording becomes a z-map: the sum over a window of W samples and 3
beams of (x - level), over the root of the sum of the spreads squared (+1 for the speckle's quantisation). At each
threshold the target's best window near its true place (the truth file: +-2 beams, +-20 samples) is a hit; the
water's best window away from every target (+-3 beams, +-40 samples) is a false alarm. Since the detector is told
where each target is, its recall at a threshold is the most any detector of this family reaches, and its false
windows the fewest: precision at that recall is at most hits / (hits + sweeps with a false window).

Usage: python3 tools/eval/faint_limit.py EMPTY.csv SCENE.csv SCENE.json [--window W] [--range M]
(the scenes of sonar-sim --scene faint [--empty]; docs/decisions.md, "The site survey").
"""
import argparse
import csv
import json
import math

import numpy as np


def load(path):
    return [(int(r[2]), np.array([int(x) for x in r[3].split()], dtype=float)) for r in csv.reader(open(path))]


def sweeps_of(rows):
    """The rows split where the head turns back (a sector scanned back and forth)."""
    out, cur, prev, d0 = [], [], None, None
    for a, s in rows:
        if prev is not None:
            d = np.sign(a - prev)
            if d0 is not None and d != d0:
                out.append(cur)
                cur = []
            d0 = d
        cur.append((a, s))
        prev = a
    out.append(cur)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("empty")
    ap.add_argument("scene")
    ap.add_argument("truth")
    ap.add_argument("--window", type=int, default=48, help="samples a window (default 48)")
    ap.add_argument("--range", type=float, default=15.0, help="metres (default 15)")
    a = ap.parse_args()
    emp, occ, truth = load(a.empty), load(a.scene), json.load(open(a.truth))
    n = len(emp[0][1])
    acc = {}
    for ang, s in emp:
        acc.setdefault(ang, []).append(s)
    level = {k: np.mean(v, 0) for k, v in acc.items()}
    spread = {k: np.std(v, 0) for k, v in acc.items()}
    objs = {s["sweep"]: s["objects"] for s in truth["sweeps"]}
    k1 = np.ones(a.window)
    hits, water = [], []
    for k, sw in enumerate(sweeps_of(occ)[:len(objs)]):
        sw = sorted(sw, key=lambda t: t[0])
        angles = [ang for ang, _ in sw]
        d = np.array([s - level.get(ang, np.zeros(n)) for ang, s in sw])
        v = np.array([spread.get(ang, np.ones(n)) ** 2 + 1.0 for ang, _ in sw])
        cd = np.array([np.convolve(r, k1, "same") for r in d])
        cv = np.array([np.convolve(r, k1, "same") for r in v])
        cd[1:-1] = cd[:-2] + cd[1:-1] + cd[2:]
        cv[1:-1] = cv[:-2] + cv[1:-1] + cv[2:]
        z = cd / np.sqrt(cv + 1e-9)
        away = np.ones_like(z, bool)
        for o in objs.get(k, []):
            b = (math.degrees(math.atan2(o["y"], o["x"])) % 360) / 0.9
            ai = int(np.argmin([abs(((ang - b + 200) % 400) - 200) for ang in angles]))
            ci = int(math.hypot(o["x"], o["y"]) / a.range * n)
            hits.append(z[max(0, ai - 2):ai + 3, max(0, ci - 20):ci + 20].max())
            away[max(0, ai - 3):ai + 4, max(0, ci - 40):ci + 40] = False
        away[:, :int(0.5 / a.range * n)] = False  # the ring-down
        water.append(z[away].max())
    hits, water = np.array(hits), np.array(water)
    print(f"{len(hits)} target looks in {len(water)} sweeps, window {a.window} samples x 3 beams")
    for r in (0.95, 0.90, 0.80):
        th = np.percentile(hits, 100 * (1 - r))
        tp, fp = float(np.mean(hits >= th)) * len(hits), int(np.sum(water >= th))
        print(f"recall {np.mean(hits >= th):.2f}: a false window in {fp} of {len(water)} sweeps: precision at most "
              f"{tp / (tp + fp):.2f}")


if __name__ == "__main__":
    main()
