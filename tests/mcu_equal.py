#!/usr/bin/env python3
"""mcu_equal.py -- a co-processor's sweeps (sonard --coprocessor --json) against the host's replay of the beams it was
given (sonard --replay --json): every sweep's beams, threshold, runs and groups, and its detections' count, cells and
centroids within 1 mm. Prints a line of what agreed; exits 1 on the first difference, naming it.
Usage: mcu_equal.py COPROCESSOR.jsonl REPLAY.jsonl"""
import json
import sys


def main():
    co = [json.loads(line) for line in open(sys.argv[1])]
    re = {d["sweep"]: d for d in map(json.loads, open(sys.argv[2]))}
    assert co, "no sweeps from the co-processor"
    n, per = 0, []
    for c in co:
        assert c["sweep"] in re, ("sweep %d: not in the replay" % c["sweep"])
        r = re[c["sweep"]]
        per.append(f"{c['sweep']}: {len(c['detections'])}/{len(r['detections'])}")
        for k in ("beams", "threshold", "runs", "groups"):
            assert c[k] == r[k], (c["sweep"], k, c[k], r[k])
        assert len(c["detections"]) == len(r["detections"]), (c["sweep"], len(c["detections"]), len(r["detections"]))
        for a, b in zip(c["detections"], r["detections"]):
            assert a["points"] == b["points"], (c["sweep"], a["points"], b["points"])
            assert abs(a["x_m"] - b["x_m"]) <= 0.001 and abs(a["y_m"] - b["y_m"]) <= 0.001, (c["sweep"], a, b)
            n += 1
    print(f"{len(co)} sweeps, {n} detections: counts, cells and positions (within 1 mm) equal; sweep: co-processor/replay "
          f"detections {', '.join(per)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
