#!/usr/bin/env python3
"""mavlink_reload_check.py -- after a SIGHUP that turns the output frame and moves --min-range, OBSTACLE_DISTANCE
and sonard's detections agree: each detection lies in the entry of the last OBSTACLE_DISTANCE sent before its sweep
ended that holds its bearing, at its range, before the reload and after it; the gate posts turn by the offset; min_distance
follows --min-range. Usage: mavlink_reload_check.py SONARD.jsonl OD.jsonl N1 (N1: sweeps printed when the SIGHUP went)."""
import json
import math
import sys

OFF0, OFF1 = 0.0, 100.0 * 0.9   # the reload's angle-offset: 0 then 100 gradians, in degrees
MIN0, MIN1 = 50, 200            # min_distance, cm: --min-range 0.5 then 2 m
TOL_M = 0.6                     # a detection's centroid against the nearest echo in its entry (an oblique wall's
                                # piece: 0.54 m nearer at the 12 m edge)


def entry(bearing, offset):
    """The OBSTACLE_DISTANCE entry (5 degrees each, the first centred on offset) holding bearing."""
    return int(math.floor((bearing - offset) / 5.0 + 0.5)) % 72


def main():
    sweeps = [json.loads(x) for x in open(sys.argv[1])]
    ods = [json.loads(x) for x in open(sys.argv[2])]
    n1 = int(sys.argv[3])
    # The sweep in progress when the SIGHUP came is line n1 + 1 (old settings); the new ones take over after it.
    old = [s for s in sweeps[:n1 + 1] if s["sweep"] >= 2]   # from sweep 2: the background learnt
    new = sweeps[n1 + 1:]
    assert old and len(new) >= 2, (len(old), len(new))
    ends = [s["utime"] / 1e6 for s in sweeps]
    t_new = ends[n1]   # the first new sweep starts where the SIGHUP's sweep ended

    def agree(group, min_cm, shift=0.0):
        got = []
        for s in group:
            # The last message sent before the sweep ended: the map of the beams the detections came from.
            before = [o for o in ods if o["t"] <= s["utime"] / 1e6]
            assert before, ("no OBSTACLE_DISTANCE before the end of sweep", s["sweep"])
            od = before[-1]
            assert od["min"] == min_cm, (s["sweep"], od["min"], min_cm)
            for d in s["detections"]:
                k = entry(d["bearing_deg"] + shift, od["offset"])
                cm = od["distances"][k]
                got.append((s["sweep"], round(d["bearing_deg"], 1), round(d["range_m"], 2), k,
                            None if cm >= od["max"] + 1 else cm / 100.0))
        return got

    a, b = agree(old, MIN0), agree(new, MIN1)
    for name, g in (("before", a), ("after", b)):
        ok = [x for x in g if x[4] is not None and abs(x[4] - x[2]) <= TOL_M]
        print(f"{name} the reload: {len(g)} detections, {len(ok)} in their OBSTACLE_DISTANCE entry within {TOL_M} m: {g}")
        assert g and len(ok) == len(g), g
    # The test can tell: had the map kept the old frame, the detections after the reload would sit in entries 90
    # degrees away, where the map holds something else.
    w = agree(new, MIN1, shift=OFF1 - OFF0)   # the old frame's entry k is the turned map's k + 90 degrees
    wrong = [x for x in w if x[4] is None or abs(x[4] - x[2]) > TOL_M]
    print(f"in the old frame {len(wrong)} of {len(w)} would not agree")
    assert len(wrong) >= len(w) // 2, w
    # Every OBSTACLE_DISTANCE sent once the new sweep has begun says the new min_distance; none before the SIGHUP.
    assert all(o["min"] == MIN1 for o in ods if o["t"] > t_new + 0.5), "min_distance not 200 after the reload"
    assert all(o["min"] == MIN0 for o in ods if o["t"] < ends[n1 - 1]), "min_distance 200 before the reload"
    # Nothing nearer than the new --min-range; the posts (static, the nearest detections) turned by 90 degrees.
    assert all(d["range_m"] >= 2.0 for s in new for d in s["detections"])
    # What stood still before the reload (in every sweep within a degree): the posts, the wall piece.
    still = sorted({x[1] for x in a if all(any(y[0] == sw and abs(y[1] - x[1]) <= 1.0 for y in a)
                                           for sw in {z[0] for z in a})})
    pb = sorted(x[1] for x in b)
    turned = [any(abs(((q - p) - (OFF1 - OFF0) + 180) % 360 - 180) < 1.5 for q in pb) for p in still]
    print(f"still before: {still}; after: {pb}")
    assert still and all(turned), "something still before the reload has no counterpart turned by 90 degrees after it"
    return 0


if __name__ == "__main__":
    sys.exit(main())
