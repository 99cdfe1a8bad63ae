#!/usr/bin/env python3
"""aquascan2csv.py -- AquaScan pool recordings (text matrices + YOLO labels) to the study's CSV and a truth JSON.

Input: shared/data/real/aquascan/raw_data/<batch>/sonar<N>/<time>_<idx>.txt[.gz] (400 lines
'angle v0..v499') and raw_labels/... ('<id> <state> <xc> <yc> <w> <h>', YOLO-normalised: x along
the 500 samples, y along the 400 gradians). Output per sonar: <out>/<sonar>.csv (beams in
acquisition order: even sweeps ascending, odd sweeps descending, as the recorder's
back-and-forth scheme pinged them; only pinged angles; per-beam time estimated by spreading the
sweep period, which is all the files allow) with range_m=<assumed> metadata, and
<out>/<sonar>.truth.json in tools/eval/score.py's format (sweep k = k-th file; objects at the box
centre in metres, plus the box in gradians and metres of range).

The range is NOT recorded. The recorder's default is 15 m ('--dis 15'), the evaluation script
uses 13 m, and a docstring says 20 m; --range picks one (default 15) and it is stated in every
output. Only the metric scale depends on it: detection and matching work in the same units.
"""
import argparse
import calendar
import datetime
import glob
import gzip
import json
import math
import os
import sys

N = 500


def start_time(path):
    stem = os.path.basename(path).split("_")[0]
    return calendar.timegm(datetime.datetime.strptime(stem, "%Y-%m-%d-%H-%M-%S").timetuple())


def index(path):
    return int(os.path.basename(path).split("_")[1].split(".")[0])


def read_sweep(path):
    beams = []
    with (gzip.open(path, "rt") if path.endswith(".gz") else open(path)) as f:
        for ln, line in enumerate(f, 1):
            v = line.split()
            if not v:
                continue
            s = [int(float(x)) for x in v[1:]]
            if len(s) != N:
                sys.exit(f"{path}:{ln}: {len(s)} samples, expected {N}")
            if any(s):
                beams.append((int(float(v[0])), s))
    return beams


def read_labels(path):
    out = []
    if os.path.exists(path):
        for ln, line in enumerate(open(path), 1):
            p = line.split()
            if len(p) >= 6:
                out.append((p[0], p[1]) + tuple(float(x) for x in p[2:6]))
            elif p:
                sys.exit(f"{path}:{ln}: expected '<id> <state> <xc> <yc> <w> <h>'")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("data", help="the aquascan directory (holds raw_data/ and raw_labels/)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--range", type=float, default=15.0, help="metres assumed for the 500 samples (default 15)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    dirs = sorted(glob.glob(os.path.join(a.data, "raw_data", "*", "sonar*")))
    if not dirs:
        sys.exit(f"{a.data}: no raw_data/*/sonar* directories")
    for d in dirs:
        sonar = os.path.basename(d)
        files = sorted(glob.glob(os.path.join(d, "*.txt*")), key=index)
        steps = sorted((start_time(b) - start_time(x)) / (index(b) - index(x)) for x, b in zip(files, files[1:]))
        period = steps[len(steps) // 2] if steps else 3.0
        truth = {"scene": f"aquascan {sonar}", "range_m": a.range, "samples": N, "assumed_range": True, "sweeps": []}
        labels_total = 0
        with open(os.path.join(a.out, f"{sonar}.csv"), "w") as out:
            for k, path in enumerate(files):
                beams = read_sweep(path)
                if index(path) % 2 == 1:
                    beams = beams[::-1]
                t0 = start_time(path)
                for j, (angle, s) in enumerate(beams):
                    t = t0 + j * period / len(beams)
                    sec = int(t)
                    out.write(f'{sec},{int(round((t - sec) * 1e9)):09d},{angle},"{" ".join(map(str, s))}",range_m={a.range:.4f}\n')
                lab = path.replace(os.sep + "raw_data" + os.sep, os.sep + "raw_labels" + os.sep)
                lab = lab[:-3] if lab.endswith(".gz") else lab
                objs = []
                for hid, state, xc, yc, w, h in read_labels(lab):
                    r = xc * a.range  # sample fraction -> metres (sample centres differ by half a sample)
                    g = yc * 400.0
                    th = g * math.pi / 200.0
                    objs.append({"id": f"{hid}", "state": state, "x": round(r * math.cos(th), 3), "y": round(r * math.sin(th), 3),
                                 "radius": round(max(w * a.range, h * 400 * 0.9 * math.pi / 180 * r) / 2, 3),
                                 "box_gradians": [round((yc - h / 2) * 400, 2), round((yc + h / 2) * 400, 2)],
                                 "box_range_m": [round((xc - w / 2) * a.range, 3), round((xc + w / 2) * a.range, 3)]})
                labels_total += len(objs)
                # no label file: the truth of this sweep is unknown, not "nobody there"
                truth["sweeps"].append({"sweep": k, "file": os.path.basename(path), "labelled": os.path.exists(lab),
                                        "objects": objs})
        json.dump(truth, open(os.path.join(a.out, f"{sonar}.truth.json"), "w"))
        unl = sum(1 for x in truth["sweeps"] if not x["labelled"])
        print(f"{sonar}: {len(files)} sweeps ({unl} without labels, not scored), {labels_total} labelled people -> "
              f"{a.out}/{sonar}.csv (range assumed {a.range} m)")


if __name__ == "__main__":
    main()
