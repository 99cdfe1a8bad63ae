#!/usr/bin/env python3
"""tank_calib.py -- the tank's acoustics measured on real sweeps, for sonar-sim's "tank" scene (tools/sim/scene.c): how
strong a wall's echoes come back at twice and three times its range, and how often whole-beam streaks come and how far
they stand above their neighbours. Alone:

  .venv/bin/python tools/eval/tank_calib.py ../shared/data/real/duke/session-2024-63sweeps.csv.gz [--beams 101]

On raw samples (5-sample means along the beam; the first 130 samples left out: the team's zeros and the ring-down). A
beam's wall is its strongest echo when that is at least 120 and nearer than 2.4 m (so that three times its range is in
the recording); its echo at m times the range is the strongest sample within 8 % of m times the wall's, as a share of
the wall's. A streak is a beam 15 levels above the median of the beams two and three either side on at least 30 % of
its length. Needs numpy (the evaluation venv).
"""
import argparse
import gzip

import numpy as np


def load(path):
    opener = gzip.open if path.endswith(".gz") else open
    rows = []
    with opener(path, "rt") as f:
        for line in f:
            p = line.split(",", 3)
            if len(p) == 4 and p[0][:1].isdigit():
                rows.append(np.array(p[3].strip().strip('"').split(), dtype=float))
    n = min(len(r) for r in rows)
    return np.array([r[:n] for r in rows])


def smooth(v, k):
    return np.convolve(v, np.ones(k) / k, mode="same")


def echoes(M, range_m):
    n = M.shape[1]
    rr = (np.arange(n) + 0.5) * range_m / n
    out = {2: [], 3: []}
    for b in M:
        x = smooth(b, 9)
        x[:130] = 0
        w = int(np.argmax(x))
        if x[w] < 120 or rr[w] > 2.4:
            continue
        for m in (2, 3):
            c = int(round((w + 0.5) * m - 0.5))
            if c + 40 >= n:
                continue
            h = int(0.08 * c)
            out[m].append(x[c - h:c + h + 1].max() / x[w])
    return out


def streaks(M, beams):
    S = M[:, 130:]
    rate, excess, runs = 0, [], []
    for k in range(len(S) // beams):
        sw = np.array([smooth(v, 5) for v in S[k * beams:(k + 1) * beams]])
        lit = []
        for b in range(beams):
            nb = [j for j in (b - 3, b - 2, b + 2, b + 3) if 0 <= j < beams]
            d = sw[b] - np.median(sw[nb], axis=0)
            on = (d > 15).mean() >= 0.3
            lit.append(on)
            if on:
                excess.append(np.median(d[d > 15]))
        r = 0
        for on in lit + [False]:
            if on:
                r += 1
            elif r:
                runs.append(r)
                r = 0
    total = (len(S) // beams) * beams
    return sum(runs) / max(1, total), float(np.median(excess)) if excess else 0.0, runs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--range", type=float, default=5.0)
    ap.add_argument("--beams", type=int, default=101, help="beams a sweep")
    a = ap.parse_args()
    M = load(a.csv)
    e = echoes(M, a.range)
    for m in (2, 3):
        v = np.array(e[m])
        print(f"echo at {m}x the wall's range: median {np.median(v):.3f} of the wall's level "
              f"(quartiles {np.percentile(v, 25):.3f}-{np.percentile(v, 75):.3f}, {len(v)} beams)")
    rate, excess, runs = streaks(M, a.beams)
    widths = {w: runs.count(w) for w in sorted(set(runs))}
    print(f"streaks: {100 * rate:.2f} % of beams, {excess:.1f} levels above their neighbours (median), runs {widths}")


if __name__ == "__main__":
    main()
