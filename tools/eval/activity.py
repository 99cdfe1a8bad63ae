#!/usr/bin/env python3
"""activity.py -- sonard's track activity (moving, standing, struggling) and struggle alarms scored against labelled
people: a confusion table of each labelled person-sweep's state against the activity of the track matched to it (tracks
confirmed or coasting, least total distance within the gate), the share covered by a track with a known activity, and
when each struggler's alarm was first raised (its labelled looks counted from 1). Labels: AquaScan's states (stand,
struggle, moving) or sonar-sim's activity (standing, struggling, moving). stdlib only.
  activity.py TRUTH.json SONARD.jsonl [--from-sweep K] [--label TEXT] [--check]
--check fails unless issue 46's targets hold: covered >= 75 %, standing vs struggling accuracy >= 0.9 with <= 5 % of
standing called struggling, moving called moving >= 85 %, every struggler alarmed by its fourth labelled look (within
three looks of its first: one to be seen, two windows, two verdicts); with --sim (the simulated pools) also no stander
or swimmer alarmed for struggling.
"""
import argparse
import json
import sys

from score import assign, pair_dist

STATES = {"stand": "standing", "standing": "standing", "struggle": "struggling", "struggling": "struggling",
          "moving": "moving"}
ACTS = ("moving", "standing", "struggling", "unknown")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("truth")
    ap.add_argument("detections")
    ap.add_argument("--from-sweep", type=int, default=2, help="first labelled sweep scored (default 2: the third)")
    ap.add_argument("--gate", type=float, default=1.0)
    ap.add_argument("--label", default="")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--sim", action="store_true", help="with --check: no stander or swimmer alarmed (simulated pools)")
    a = ap.parse_args()
    truth = json.load(open(a.truth))
    lines = {}
    for ln in open(a.detections):
        if ln.strip():
            d = json.loads(ln)
            lines[d["sweep"]] = d
    table = {s: {k: 0 for k in ACTS + ("no track",)} for s in ("standing", "struggling", "moving")}
    looks, alarmed, false_alarms, corrs = {}, {}, [], {}
    for sw in truth["sweeps"]:
        if not sw.get("labelled", True):
            continue
        k = sw["sweep"]
        objs = [o for o in sw["objects"] if STATES.get(o.get("state", o.get("activity"))) is not None]
        for o in objs:
            looks.setdefault(o["id"], 0)
            looks[o["id"]] += 1
        if k < a.from_sweep:
            continue
        trk = [h for h in lines.get(k, {}).get("tracks", []) if h["state"] in ("confirmed", "coasting")]
        got = {}
        if trk and objs:
            cost = [[pair_dist(h, o) for h in trk] for o in objs]
            for j, i in enumerate(assign(cost)):
                if i >= 0 and cost[j][i] <= a.gate:
                    got[j] = trk[i]
        for j, o in enumerate(objs):
            s = STATES[o.get("state", o.get("activity"))]
            h = got.get(j)
            table[s]["no track" if h is None else h.get("activity", "unknown")] += 1
            if h is not None and h.get("echo_corr") is not None and h.get("activity") in ("standing", "struggling"):
                corrs.setdefault(s, []).append(h["echo_corr"])
            if h is not None and "struggle" in h.get("alarms", []):
                if s == "struggling":
                    alarmed.setdefault(o["id"], looks[o["id"]])
                else:
                    false_alarms.append((k, o["id"], s, h["id"]))
    strugglers = sorted({o["id"] for sw in truth["sweeps"] for o in sw["objects"]
                         if STATES.get(o.get("state", o.get("activity"))) == "struggling"})
    print(f"{a.label}labelled state against the matched track's activity (sweeps from {a.from_sweep}; gate {a.gate} m)")
    print(f"{a.label}  {'':12s}" + "".join(f"{c:>12s}" for c in ACTS + ("no track",)))
    for s, row in table.items():
        print(f"{a.label}  {s:12s}" + "".join(f"{row[c]:12d}" for c in ACTS + ("no track",)))
    total = sum(sum(r.values()) for r in table.values())
    known = sum(r[c] for r in table.values() for c in ("moving", "standing", "struggling"))
    ss = [table[s][c] for s in ("standing", "struggling") for c in ("moving", "standing", "struggling")]
    ss_n = sum(ss)
    ss_ok = table["standing"]["standing"] + table["struggling"]["struggling"]
    st_n = sum(table["standing"][c] for c in ("moving", "standing", "struggling"))
    mv_n = sum(table["moving"][c] for c in ("moving", "standing", "struggling"))
    cover = known / total if total else 0.0
    acc = ss_ok / ss_n if ss_n else 0.0
    st_bad = table["standing"]["struggling"] / st_n if st_n else 0.0
    mv_ok = table["moving"]["moving"] / mv_n if mv_n else 0.0
    print(f"{a.label}covered by a track with a known activity: {known} of {total} person-sweeps ({100 * cover:.0f} %)")
    print(f"{a.label}standing vs struggling accuracy {acc:.2f} ({ss_ok} of {ss_n}); standing called struggling "
          f"{100 * st_bad:.1f} %; moving called moving {100 * mv_ok:.0f} % ({table['moving']['moving']} of {mv_n})")
    for s, v in sorted(corrs.items()):
        v.sort()
        print(f"{a.label}echo correlation of the still ones labelled {s}: min {v[0]:.2f}, median {v[len(v) // 2]:.2f}, "
              f"max {v[-1]:.2f} ({len(v)})")
    for p in strugglers:
        print(f"{a.label}struggler {p}: struggle alarm first at its labelled look "
              f"{alarmed[p] if p in alarmed else 'never'} of {looks.get(p, 0)}")
    print(f"{a.label}struggle alarms on people not struggling: {len(false_alarms)}"
          + "".join(f"; sweep {k} person {i} ({s}) track {t}" for k, i, s, t in false_alarms[:5]))
    if not a.check:
        return 0
    within = 4  # its first look, two windows, two verdicts: three looks after the first is the soonest
    bad = []
    if cover < 0.75:
        bad.append(f"covered {cover:.2f} < 0.75")
    if ss_n and (acc < 0.9 or st_bad > 0.05):
        bad.append(f"standing vs struggling {acc:.2f} (< 0.9?), standing called struggling {st_bad:.2f} (> 0.05?)")
    if mv_n and mv_ok < 0.85:
        bad.append(f"moving called moving {mv_ok:.2f} < 0.85")
    for p in strugglers:
        if alarmed.get(p, 99) > within:
            bad.append(f"struggler {p} not alarmed by its look {within}")
    if a.sim and false_alarms:
        bad.append(f"{len(false_alarms)} struggle alarms on others")
    for b in bad:
        print(f"{a.label}FAIL: {b}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
