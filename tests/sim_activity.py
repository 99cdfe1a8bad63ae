#!/usr/bin/env python3
"""sim_activity.py -- sonar-sim's activity scene against the feature that tells standing from struggling on the AquaScan
recordings (issue 46): the raw echo in a fixed window at a person (+-0.5 m by +-7.5 gradians) correlated with the same
window one look earlier, averaged over three looks. A standing body is a steady reflector (high), a struggling one
decorrelates (low); the swimmer is not judged here. Checks each person-look from the fourth on against the thresholds
the recordings gave (standing above 0.37, struggling below 0.32). stdlib only.
  sim_activity.py scene.csv truth.json
"""
import csv
import json
import math
import sys


def looks(path, per_turn):
    """Each turn's beams by angle: [{angle: [samples]}]."""
    turns, cur = [], {}
    with open(path) as f:
        for i, row in enumerate(csv.reader(f)):
            if i % per_turn == 0 and cur:
                turns.append(cur)
                cur = {}
            cur[int(row[2])] = [int(v) for v in row[3].split()]
    if cur:
        turns.append(cur)
    return turns


def window(turn, x, y, range_m, n):
    r, a = math.hypot(x, y), (math.degrees(math.atan2(y, x)) / 0.9) % 400
    i0, i1 = max(0, int((r - 0.5) / range_m * n)), min(n, int((r + 0.5) / range_m * n) + 1)
    out = []
    for ang in sorted(turn):
        d = abs((ang - a + 200) % 400 - 200)
        if d <= 7.5:
            out.extend(turn[ang][i0:i1])
    return out


def corr(u, v):
    if len(u) != len(v) or len(u) < 3:
        return None
    mu, mv = sum(u) / len(u), sum(v) / len(v)
    su = math.sqrt(sum((p - mu) ** 2 for p in u))
    sv = math.sqrt(sum((q - mv) ** 2 for q in v))
    return sum((p - mu) * (q - mv) for p, q in zip(u, v)) / (su * sv) if su > 0 and sv > 0 else 0.0


def main():
    truth = json.load(open(sys.argv[2]))
    turns = looks(sys.argv[1], truth["beams_per_sweep"])
    rng, n = truth["range_m"], truth["samples"]
    hist, ok, bad = {}, 0, 0
    for k, sw in enumerate(truth["sweeps"][: len(turns)]):
        for o in sw["objects"]:
            act = o.get("activity")
            if act not in ("standing", "struggling") or k == 0:
                continue
            c = corr(window(turns[k], o["x"], o["y"], rng, n), window(turns[k - 1], o["x"], o["y"], rng, n))
            h = hist.setdefault(o["id"], [])
            h.append(c)
            if len(h) < 3:
                continue
            m = sum(h[-3:]) / 3
            good = m > 0.37 if act == "standing" else m < 0.32
            ok, bad = ok + good, bad + (not good)
            print(f"sweep {k}: {o['id']} ({act}): correlation {h[-1]:.2f}, over 3 looks {m:.2f}: {'as labelled' if good else 'NOT as labelled'}")
    print(f"sim_activity: {ok} person-looks as labelled, {bad} not")
    sys.exit(0 if ok > 0 and bad == 0 else 1)


if __name__ == "__main__":
    main()
