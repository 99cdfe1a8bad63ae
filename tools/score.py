#!/usr/bin/env python3
"""score.py -- scores sonard --json detections against a simulator truth file (stdlib only).

A detection is a true positive when its centroid lies within --gate metres of a not yet matched
truth object of the same sweep (closest pairs first); other detections are false positives,
unmatched objects false negatives. Sweeps marked "labelled": false (no label file) are skipped. Prints precision, recall, F1, centroid error and false alarms
per sweep; with --min-precision/--min-recall/--min-f1/--max-error it exits 1 when a target is missed.
"""
import argparse
import json
import math
import sys


def match(dets, objs, gate):
    pairs = sorted((math.hypot(d["x_m"] - o["x"], d["y_m"] - o["y"]), i, j)
                   for i, d in enumerate(dets) for j, o in enumerate(objs))
    used_d, used_o, errs = set(), set(), []
    for dist, i, j in pairs:
        if dist > gate or i in used_d or j in used_o:
            continue
        used_d.add(i)
        used_o.add(j)
        errs.append(dist)
    return len(errs), len(dets) - len(errs), len(objs) - len(errs), errs


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("truth")
    ap.add_argument("detections", help="sonard --json output, one line per sweep")
    ap.add_argument("--gate", type=float, default=1.0, help="match distance, metres (default 1.0)")
    ap.add_argument("--min-precision", type=float)
    ap.add_argument("--min-recall", type=float)
    ap.add_argument("--min-f1", type=float)
    ap.add_argument("--max-error", type=float, help="largest mean centroid error, metres")
    ap.add_argument("--label", default="")
    ap.add_argument("--verbose", action="store_true")
    a = ap.parse_args()
    # sweeps marked "labelled": false have unknown truth: neither their detections nor their objects count
    truth = {s["sweep"]: s["objects"] for s in json.load(open(a.truth))["sweeps"] if s.get("labelled", True)}
    sweeps = {}
    for n, line in enumerate(open(a.detections), 1):
        line = line.strip()
        if not line:
            continue
        try:
            d = json.loads(line)
        except json.JSONDecodeError as e:
            sys.exit(f"{a.detections}:{n}: not JSON: {e}")
        sweeps[d["sweep"]] = d["detections"]
    tp = fp = fn = 0
    errs = []
    for k in sorted(truth):
        dets = sweeps.get(k, [])
        t, f, m, e = match(dets, truth[k], a.gate)
        tp, fp, fn = tp + t, fp + f, fn + m
        errs += e
        if a.verbose:
            print(f"  sweep {k}: {len(truth[k])} objects, {len(dets)} detections, TP {t} FP {f} FN {m}"
                  + (f", error {sum(e) / len(e):.3f} m" if e else ""))
    p = tp / (tp + fp) if tp + fp else 1.0
    r = tp / (tp + fn) if tp + fn else 1.0
    f1 = 2 * p * r / (p + r) if p + r else 0.0
    err = sum(errs) / len(errs) if errs else float("nan")
    worst = max(errs) if errs else float("nan")
    far = fp / max(1, len(truth))
    print(f"{a.label}precision {p:.3f}  recall {r:.3f}  F1 {f1:.3f}  centroid error mean {err:.3f} m max {worst:.3f} m"
          f"  false alarms/sweep {far:.2f}  (TP {tp} FP {fp} FN {fn}, {len(truth)} sweeps)")
    ok = True
    if a.min_precision is not None and p < a.min_precision:
        print(f"FAIL: precision {p:.3f} < {a.min_precision}")
        ok = False
    if a.min_recall is not None and r < a.min_recall:
        print(f"FAIL: recall {r:.3f} < {a.min_recall}")
        ok = False
    if a.min_f1 is not None and f1 < a.min_f1:
        print(f"FAIL: F1 {f1:.3f} < {a.min_f1}")
        ok = False
    if a.max_error is not None and not (err <= a.max_error):
        print(f"FAIL: centroid error {err:.3f} m > {a.max_error} m")
        ok = False
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
