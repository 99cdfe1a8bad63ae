"""far_swimmer.py -- why a labelled person is or is not found by the occupied-pool preset (issue 52's person 5 on AquaScan
sonar4): each sweep's foreground recomputed as the preset makes it (the 5 x 5 median over beams and samples, less the
median across the sweep's beams at each range: the study's range background), and, within 0.5 m of where the person is
labelled, how many cells stand above that sweep's global threshold (sonard's own, from its --json) and the contrast of
the min-points-th strongest; the same for the other labelled people. Prints one JSON object.

  .venv/bin/python tools/eval/far_swimmer.py REC.csv TRUTH.json PRESET.jsonl --person 5 [--range 15] [--min-points 40]
      [--track-points 25]

numpy and scipy (the evaluation's venv).
"""
import argparse
import csv
import json
import math
import statistics

import numpy as np
from scipy.ndimage import median_filter

NEAR_M = 0.5  # cells within this of a labelled centre are the person's


def contrasts(cells, threshold, k):
    """(cells above the threshold, the k-th strongest cell's contrast; 0 when there are fewer)."""
    s = np.sort(cells)[::-1]
    return int((cells > threshold).sum()), int(s[k - 1]) if s.size >= k else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("truth")
    ap.add_argument("jsonl", help="sonard --json output under the preset (its sweeps' times and thresholds)")
    ap.add_argument("--person", required=True)
    ap.add_argument("--range", type=float, default=15.0)
    ap.add_argument("--min-points", type=int, default=40)
    ap.add_argument("--track-points", type=int, default=25)
    a = ap.parse_args()
    rows = []
    with open(a.csv) as f:
        for n, r in enumerate(csv.reader(f), 1):
            try:
                rows.append((int(r[0]) * 1_000_000 + int(r[1]) // 1000, float(r[2]), np.array(r[3].split(), dtype=float)))
            except (ValueError, IndexError):
                raise SystemExit(f"far_swimmer: {a.csv}:{n}: not a row of the study's CSV (sec,nsec,angle,samples)")
    truth = {s["sweep"]: s for s in json.load(open(a.truth))["sweeps"]}
    out = [json.loads(x) for x in open(a.jsonl)]
    per, prev = [], -1
    for d in out:
        beams = [r for r in rows if prev < r[0] <= d["utime"]]
        prev = d["utime"]
        s = truth.get(d["sweep"])
        if s is None or not beams or len({b[2].size for b in beams}) != 1:
            continue
        who = [o for o in s["objects"] if str(o["id"]) == a.person]
        if not who:
            continue
        x = np.stack([b[2] for b in beams])
        m = median_filter(x, size=(5, 5), mode="nearest")
        fg = np.clip(m - np.median(m, axis=0), 0, None)
        r = (np.arange(x.shape[1]) + 0.5) * a.range / x.shape[1]
        th = np.deg2rad(np.array([b[1] for b in beams]) * 0.9)[:, None]
        cx, cy = r[None, :] * np.cos(th), r[None, :] * np.sin(th)
        thr = d["threshold"]
        row = {"sweep": d["sweep"], "threshold": thr,
               "found": any(math.hypot(q["x_m"] - who[0]["x"], q["y_m"] - who[0]["y"]) < 1.0 for q in d["detections"])}
        row["above"], row["kth"] = contrasts(fg[np.hypot(cx - who[0]["x"], cy - who[0]["y"]) < NEAR_M], thr, a.min_points)
        row["range_m"] = round(math.hypot(who[0]["x"], who[0]["y"]), 1)
        row["others_kth"] = [contrasts(fg[np.hypot(cx - o["x"], cy - o["y"]) < NEAR_M], thr, a.min_points)[1]
                             for o in s["objects"] if str(o["id"]) != a.person]
        per.append(row)
    if not per:
        raise SystemExit(f"far_swimmer: person {a.person} is in no sweep of {a.truth} that {a.jsonl} has")
    others = [v for p in per for v in p["others_kth"]]
    print(json.dumps({
        "person": a.person, "sweeps": len(per), "found": sum(p["found"] for p in per),
        "range_m": [min(p["range_m"] for p in per), max(p["range_m"] for p in per)],
        "enough_for_a_track": sum(p["above"] >= a.track_points for p in per),
        "enough_for_a_birth": sum(p["above"] >= a.min_points for p in per),
        "kth_median": statistics.median(p["kth"] for p in per),
        "threshold_median": statistics.median(p["threshold"] for p in per),
        "others_kth_median": statistics.median(others) if others else None,
        "min_points": a.min_points, "track_points": a.track_points, "per_sweep": per}))


if __name__ == "__main__":
    main()
