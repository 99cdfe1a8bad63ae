"""transients.py -- the water's transient echoes as sonard's detector sees them: how many are born a sweep at each range,
how big and bright they are, how long they last and how far they move; and what stays (persistent places). Measures an
emptied recording (tools/eval/empty_site.py) to calibrate the simulator's transient clutter (sonar-sim --transients),
and the simulator's scenes to check it.

  python3 tools/eval/transients.py DETECTIONS.jsonl [--range 15] [--json]

DETECTIONS.jsonl: sonard --json. A detection continues the nearest one of the sweep before within 1.5 m (closest pairs
first); a chain that is there in half the sweeps or more is a persistent place (a wall's corner, a ladder), every other
chain a transient. stdlib only.
"""
import argparse
import json
import math

from score import pairs

LINK_M = 1.5
BANDS = (0.0, 3.0, 6.0, 9.0, 12.0, 15.0)


def chains(lines):
    """Each chain: [(sweep, detection), ...] in sweep order."""
    done, open_ = [], []
    for k, d in enumerate(lines):
        dets = d["detections"]
        took_c, took_d, nxt = set(), set(), []
        for i, j, _ in pairs([(c[-1][1]["x_m"], c[-1][1]["y_m"]) for c in open_], [(x["x_m"], x["y_m"]) for x in dets],
                             LINK_M):
            took_c.add(i)
            took_d.add(j)
            open_[i].append((k, dets[j]))
            nxt.append(open_[i])
        done += [c for i, c in enumerate(open_) if i not in took_c]
        nxt += [[(k, x)] for j, x in enumerate(dets) if j not in took_d]
        open_ = nxt
    return done + open_


def band(r):
    for lo, hi in zip(BANDS, BANDS[1:]):
        if lo <= r < hi:
            return f"{lo:.0f}-{hi:.0f}"
    return f">{BANDS[-1]:.0f}"


def measure(lines):
    """The statistics as a dict (also what --json prints)."""
    n = len(lines)
    cs = chains(lines)
    persistent = [c for c in cs if len(c) * 2 >= n]
    trans = [c for c in cs if len(c) * 2 < n]
    per_band = {}
    for c in trans:
        b = band(c[0][1]["range_m"])
        per_band.setdefault(b, []).append(c)
    out = {"sweeps": n, "detections_a_sweep": sum(len(d["detections"]) for d in lines) / max(1, n),
           "persistent_places": len(persistent),
           "persistent_a_sweep": sum(len(c) for c in persistent) / max(1, n),
           "transient_a_sweep": sum(len(c) for c in trans) / max(1, n),
           "born_a_sweep": len(trans) / max(1, n), "bands": {}}
    for b in sorted(per_band, key=lambda s: float(s.strip(">").split("-")[0])):
        cl = per_band[b]
        dets = [x for c in cl for _, x in c]
        steps = [math.hypot(c[i + 1][1]["x_m"] - c[i][1]["x_m"], c[i + 1][1]["y_m"] - c[i][1]["y_m"])
                 for c in cl for i in range(len(c) - 1)]
        out["bands"][b] = {
            "born_a_sweep": len(cl) / max(1, n),
            "life_sweeps": sum(len(c) for c in cl) / len(cl),
            "lasting_1": sum(1 for c in cl if len(c) == 1) / len(cl),
            "step_m": sum(steps) / len(steps) if steps else 0.0,
            "points": sorted(x["points"] for x in dets)[len(dets) // 2],
            "area_m2": sorted(x["area_m2"] for x in dets)[len(dets) // 2],
            "intensity": sorted(x["mean_intensity"] for x in dets)[len(dets) // 2],
        }
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("detections")
    ap.add_argument("--json", action="store_true", help="the figures as JSON")
    ap.add_argument("--label", default="")
    a = ap.parse_args()
    m = measure([json.loads(l) for l in open(a.detections)])
    if a.json:
        print(json.dumps(m))
        return
    print(f"{a.label}{m['sweeps']} sweeps: {m['detections_a_sweep']:.2f} detections a sweep; "
          f"{m['persistent_places']} persistent places ({m['persistent_a_sweep']:.2f} a sweep); transients "
          f"{m['transient_a_sweep']:.2f} a sweep, {m['born_a_sweep']:.2f} born a sweep")
    for b, s in m["bands"].items():
        print(f"{a.label}  {b} m: born {s['born_a_sweep']:.2f} a sweep, lasting {s['life_sweeps']:.2f} sweeps "
              f"({s['lasting_1'] * 100:.0f} % one), moving {s['step_m']:.2f} m a sweep; median {s['points']} points, "
              f"{s['area_m2']:.3f} m2, intensity {s['intensity']:.1f}")


if __name__ == "__main__":
    main()
