#!/usr/bin/env python3
"""score_live.py -- scores a live run on the wall clock: sonar-feed --scene-clock wall --truth (the objects every
0.1 s and each beam served) against sonard --json (stdlib only).

Tracking is scored at each publication (a JSON line, after --warmup), whatever the order of the beams: the visible
objects in range at its time are the truth, and its confirmed and coasting tracks, each predicted to that time with its
velocity, are the hypotheses; score.py's CLEAR-MOT, IDF1, ID switches and velocity error then apply as to sweeps
(faded objects are don't-care). With --every S the instants are fixed instead (every S seconds, the last publication's
tracks predicted to each): what a consumer holding the latest message sees.

The head's schedule comes from the beams served: an object is looked at by a beam within half a step (--step) of its
true bearing then; looks closer than --pass apart are one look (a window of beams). Revisit: the intervals between
looks at each object while it stays visible, after the warm-up (median and 95th percentile over all of them, and the longest). The
longest unvisited angle: over the sweep grid (every --step gradians), the longest time with no beam within half a step,
the run's end included.
"""
import argparse
import bisect
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from score import score_tracks  # noqa: E402


def load_truth(path):
    beams, frames = [], []
    with open(path) as f:
        for line in f:
            r = json.loads(line)
            if "beam" in r:
                beams.append((r["t_us"], r["beam"]))
            else:
                frames.append(r)
    return beams, frames


def load_sweeps(path):
    out = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line.startswith("{"):
                out.append(json.loads(line))
    out.sort(key=lambda s: s["utime"])
    return out


def pct(xs, p):
    if not xs:
        return float("nan")
    s = sorted(xs)
    return s[min(len(s) - 1, int(len(s) * p / 100.0))]


def grad_of(x, y):
    return (math.degrees(math.atan2(y, x)) / 0.9) % 400.0


def gap(a, b):
    d = abs(a - b) % 400.0
    return min(d, 400.0 - d)


def where(frames, ftimes, oid, u):
    """Object oid's sonar-frame position at u (us), from the nearest truth line at or before it (0.1 s apart)."""
    i = max(0, bisect.bisect_right(ftimes, u) - 1)
    for k in (i, i + 1, i - 1):
        if 0 <= k < len(frames):
            for o in frames[k]["objects"]:
                if o["id"] == oid:
                    return o["bx"], o["by"]
    return float("inf"), float("inf")


def stalled_us(stalls, a, b):
    """Microseconds of the stalls ((start, end) us) within [a, b]."""
    return sum(max(0, min(y, b) - max(x, a)) for x, y in stalls)


def revisit(beams, frames, t0, step, merge_us, stalls=()):
    """Intervals (us) between looks at each visible object after t0, and the longest unvisited grid angle (us), each
    unvisited stretch less the machine's stalls within it (stalls: (start, end) us; none: as measured)."""
    ftimes = [fr["t_us"] for fr in frames]
    last, gaps, worst = {}, [], {}
    for t, a in beams:
        k = bisect.bisect_right(ftimes, t) - 1
        if k < 0:
            continue
        # An object out of sight (gone, out of range, faded) starts afresh: its absence is not a revisit.
        seen = {o["id"] for o in frames[k]["objects"] if o["visible"]}
        for oid in [i for i in last if i not in seen]:
            del last[oid]
        for o in frames[k]["objects"]:
            if not o["visible"]:
                continue
            if gap(grad_of(o["bx"], o["by"]), a) > step / 2.0 + 1e-6:
                continue
            p = last.get(o["id"])
            if p is not None and t - p > merge_us and t >= t0:
                gaps.append(t - p)
                worst[o["id"]] = max(worst.get(o["id"], 0), t - p)
            if p is None or t - p > merge_us:
                last[o["id"]] = t
    end = beams[-1][0] if beams else t0
    unvisited = 0
    for g in range(0, 400, step):
        prev = None
        for t, a in beams:
            if gap(a, g) <= step / 2.0 + 1e-6:
                if prev is not None and t >= t0:
                    unvisited = max(unvisited, t - max(prev, t0) - stalled_us(stalls, max(prev, t0), t))
                prev = t
        if prev is not None:
            unvisited = max(unvisited, end - max(prev, t0) - stalled_us(stalls, max(prev, t0), end))
    return gaps, worst, unvisited


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("truth", help="sonar-feed --truth FILE")
    ap.add_argument("detections", help="sonard --json output")
    ap.add_argument("--every", type=float, default=0.0, help="seconds between fixed scoring instants (default 0: each publication)")
    ap.add_argument("--at", choices=("own", "publication"), default="own",
                    help="own (default): each track against where its object was at the time of the track's own state "
                         "(as score.py scores a replay); publication: predicted to the publication's (or instant's) time")
    ap.add_argument("--warmup", type=float, default=16.0, help="scene seconds left out at the start (default 16)")
    ap.add_argument("--step", type=int, default=4, help="the sweep's gradians a step (default 4)")
    ap.add_argument("--pass-s", type=float, default=0.3, help="looks closer than this are one (default 0.3 s)")
    ap.add_argument("--gate", type=float, default=1.0, help="match distance, metres (default 1.0)")
    ap.add_argument("--stalls", help="tests/stallwatch.py's file: the machine's stalls, taken out of unvisited stretches")
    ap.add_argument("--label", default="")
    ap.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    ap.add_argument("--min-idf1", type=float)
    ap.add_argument("--min-mota", type=float)
    ap.add_argument("--max-revisit-p95", type=float, help="seconds")
    ap.add_argument("--max-unvisited", type=float, help="seconds")
    a = ap.parse_args()
    beams, frames = load_truth(a.truth)
    sweeps = load_sweeps(a.detections)
    if not frames or not beams:
        print(f"{a.truth}: no objects or no beams", file=sys.stderr)
        return 2
    start = frames[0]["t_us"] - int(frames[0]["t"] * 1e6)
    t0 = start + int(a.warmup * 1e6)
    end = min(frames[-1]["t_us"], sweeps[-1]["utime"] if sweeps else frames[-1]["t_us"])
    ftimes = [fr["t_us"] for fr in frames]
    stimes = [s["utime"] for s in sweeps]
    truth, hidden, lines = {}, {}, {}
    if a.every > 0:
        instants = list(range(t0, end + 1, int(a.every * 1e6)))
    else:
        instants = [u for u in stimes if t0 <= u <= end]
    for k, t in enumerate(instants):
        i = bisect.bisect_right(ftimes, t) - 1
        j = bisect.bisect_right(stimes, t) - 1
        if i >= 0:
            objs = [{"id": o["id"], "x": o["bx"], "y": o["by"], "vx": o["vx"], "vy": o["vy"], "t_us": t}
                    for o in frames[i]["objects"]]
            if a.at == "own":
                for o in objs:
                    o["pos_at"] = (lambda oid: lambda u: where(frames, ftimes, oid, u))(o["id"])
            vis = {o["id"] for o in frames[i]["objects"] if o["visible"]}
            truth[k] = [o for o in objs if o["id"] in vis]
            hidden[k] = [o for o in objs if o["id"] not in vis]
            lines[k] = {"tracks": sweeps[j].get("tracks", []) if j >= 0 else []}
    m = score_tracks(truth, lines, a.gate, hidden=hidden)
    stalls = []
    if a.stalls:
        sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests"))
        import stallwatch  # noqa: E402
        stalls = [(int(x * 1e6), int(y * 1e6)) for x, y in stallwatch.load(a.stalls)]
    gaps, worst, unvisited = revisit(beams, frames, t0, a.step, int(a.pass_s * 1e6), stalls)
    m["stalls"] = len(stalls)
    m["stalled_s"] = sum(y - x for x, y in stalls) * 1e-6
    m.update({"revisit_median_s": pct(gaps, 50) * 1e-6, "revisit_p95_s": pct(gaps, 95) * 1e-6,
              "revisit_max_s": max(gaps) * 1e-6 if gaps else float("nan"), "looks": len(gaps),
              "unvisited_max_s": unvisited * 1e-6, "instants": len(truth),
              "beams": len(beams), "seconds": (beams[-1][0] - beams[0][0]) * 1e-6 if beams else 0.0})
    if a.json:
        print(json.dumps(m))
    else:
        print(f"{a.label}revisit median {m['revisit_median_s']:.2f} s p95 {m['revisit_p95_s']:.2f} s "
              f"max {m['revisit_max_s']:.2f} s ({m['looks']} looks)  unvisited max {m['unvisited_max_s']:.2f} s  "
              f"MOTA {m['mota']:.3f} IDF1 {m['idf1']:.3f} ID switches {m['idsw']} ({m['idsw_per_100']:.2f}/100)  "
              f"velocity error {m['vel_err']:.3f} m/s (n {m['vel_n']})  [{m['instants']} instants, {m['beams']} beams]")
    bad = []
    if a.min_idf1 is not None and not m["idf1"] >= a.min_idf1:
        bad.append(f"IDF1 {m['idf1']:.3f} < {a.min_idf1}")
    if a.min_mota is not None and not m["mota"] >= a.min_mota:
        bad.append(f"MOTA {m['mota']:.3f} < {a.min_mota}")
    if a.max_revisit_p95 is not None and not m["revisit_p95_s"] <= a.max_revisit_p95:
        bad.append(f"revisit p95 {m['revisit_p95_s']:.2f} s > {a.max_revisit_p95}")
    if a.max_unvisited is not None and not m["unvisited_max_s"] <= a.max_unvisited:
        bad.append(f"unvisited {m['unvisited_max_s']:.2f} s > {a.max_unvisited}")
    for b in bad:
        print(f"{a.label}FAIL: {b}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
