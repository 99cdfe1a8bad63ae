#!/usr/bin/env python3
"""empty_site.py -- a labelled real recording with its people taken out (real water with nobody in it), and what sonard reports on it.

  empty_site.py make CSV TRUTH.json --out PREFIX [--widen-gradians 6] [--widen-m 0.5]
  empty_site.py count SONARD.jsonl [--sweeps A:B] [--max-tracks X] [--max-alarms N] [--label TEXT]

make: every cell (beam, sample) inside a labelled person's box widened by --widen-gradians and --widen-m
takes the same cell (same gradian, same sample) of the nearest sweep in time whose boxes do not cover it;
where every sweep covers it (a person who stood there throughout), the same sample of the nearest beam of
the same sweep a few gradians away that no box covers. A sweep without a label file is unknown, not empty:
it takes the boxes of the labelled sweeps either side. Beam times, angles and metadata are kept. Writes
PREFIX.csv and PREFIX.truth.json (every sweep labelled, nobody in it; "emptied" counts the cells replaced
and how). What it cannot take out: a person's acoustic shadow behind the box and any echo of them outside
it (multipath), both left as the water's.

count: per sonard --json line, the confirmed tracks other than "static since start" (the places present
since the first look, which stay objects without a survey), those, and the alarms raised (any kind, from
each track's "alarms"); prints the mean a sweep and the distinct track IDs. --max-tracks / --max-alarms
make it exit 1 when exceeded. stdlib only.
"""
import argparse
import csv
import json
import sys


def read_rows(path):
    """-> [(sec, nsec, angle, samples list, metadata fields)] of the study's CSV as aquascan2csv writes it."""
    rows = []
    with open(path, newline="") as f:
        for ln, r in enumerate(csv.reader(f), 1):
            if not r or not r[0][:1].isdigit():
                continue
            try:
                rows.append((r[0], r[1], int(r[2]), [int(x) for x in r[3].split()], r[4:]))
            except (IndexError, ValueError) as e:
                sys.exit(f"{path}:{ln}: not a 'sec,nsec,angle,\"samples\",...' row ({e})")
    return rows


def sweep_of(rows, max_step=20):
    """Sweep index per row, cut as sonard cuts a back-and-forth sector (a reversal, a wrap or a jump ends one)."""
    out, k, last, d = [], 0, None, 0
    for r in rows:
        a = r[2]
        if last is not None:
            delta = ((a - last + 600) % 400) - 200
            if delta:
                s = 1 if delta > 0 else -1
                if abs(delta) > max_step or (d and s != d):
                    k, d = k + 1, 0
                else:
                    d = s
        out.append(k)
        last = a
    return out


def boxes(truth, nsweeps, wg, wm):
    """Widened boxes (g0, g1, r0, r1) per sweep; an unlabelled sweep takes its labelled neighbours'."""
    sw = {s["sweep"]: s for s in truth["sweeps"]}
    own = {k: [(o["box_gradians"][0] - wg, o["box_gradians"][1] + wg, o["box_range_m"][0] - wm, o["box_range_m"][1] + wm)
               for o in sw[k]["objects"]] for k in sw if sw[k].get("labelled", True)}
    out = []
    for k in range(nsweeps):
        if k in own:
            out.append(own[k])
            continue
        near = []
        for step in (-1, 1):
            j = k + step
            while 0 <= j < nsweeps and j not in own:
                j += step
            near += own.get(j, [])
        out.append(near)
    return out


def covered(bx, a, r):
    return any(g0 <= a <= g1 and r0 <= r <= r1 for g0, g1, r0, r1 in bx)


def make(a):
    rows = read_rows(a.csv)
    truth = json.load(open(a.truth))
    sw = sweep_of(rows)
    nsw = sw[-1] + 1 if sw else 0
    if nsw != len(truth["sweeps"]):
        sys.exit(f"{a.csv}: {nsw} sweeps, {a.truth}: {len(truth['sweeps'])}: not the same recording")
    rng = truth["range_m"]
    bx = boxes(truth, nsw, a.widen_gradians, a.widen_m)
    beam = {}  # (sweep, angle) -> row index
    for i, (k, r) in enumerate(zip(sw, rows)):
        beam[(k, r[2])] = i
    angles = {k: sorted(ang for (kk, ang) in beam if kk == k) for k in range(nsw)}
    order = {k: sorted(range(nsw), key=lambda j, k=k: (abs(j - k), j)) for k in range(nsw)}
    same, aside, left = 0, 0, 0
    out_rows = []
    for i, (k, r) in enumerate(zip(sw, rows)):
        s = list(r[3])
        n = len(s)
        ang = r[2]
        for q in range(n):
            rq = (q + 0.5) * rng / n
            if not covered(bx[k], ang, rq):
                continue
            for j in order[k]:
                src = beam.get((j, ang))
                if j != k and src is not None and q < len(rows[src][3]) and not covered(bx[j], ang, rq):
                    s[q] = rows[src][3][q]
                    same += 1
                    break
            else:
                for a2 in sorted(angles[k], key=lambda x: (abs(x - ang), x)):
                    src = beam[(k, a2)]
                    if a2 != ang and q < len(rows[src][3]) and not covered(bx[k], a2, rq):
                        s[q] = rows[src][3][q]
                        aside += 1
                        break
                else:
                    left += 1
        out_rows.append((r[0], r[1], ang, s, r[4]))
    with open(a.out + ".csv", "w") as f:
        for sec, nsec, ang, s, meta in out_rows:
            f.write(f'{sec},{nsec},{ang},"{" ".join(map(str, s))}"' + "".join("," + m for m in meta) + "\n")
    t = dict(truth)
    t["scene"] = truth.get("scene", "") + ", people taken out (tools/eval/empty_site.py)"
    t["sweeps"] = [{"sweep": s["sweep"], "file": s.get("file"), "labelled": True, "objects": []} for s in truth["sweeps"]]
    t["emptied"] = {"from_other_sweeps": same, "from_beams_aside": aside, "left": left,
                    "widen_gradians": a.widen_gradians, "widen_m": a.widen_m}
    json.dump(t, open(a.out + ".truth.json", "w"))
    print(f"{a.out}.csv: {len(out_rows)} beams, {nsw} sweeps; cells replaced from other sweeps {same}, "
          f"from beams aside {aside}, left as recorded {left}")


def count(a):
    lines = [json.loads(x) for x in open(a.jsonl) if x.strip()]
    lo, hi = 0, len(lines)
    if a.sweeps:
        p = a.sweeps.split(":")
        lo, hi = int(p[0] or 0), int(p[1] or len(lines))
    sel = [x for x in lines if lo <= x["sweep"] < hi]
    other, static, alarms, ids, kinds = 0, 0, [], set(), {}
    raised = set()
    for x in sel:
        for h in x.get("tracks", []):
            if h["state"] != "confirmed":
                continue
            if h.get("kind") == "static since start":
                static += 1
            else:
                other += 1
                ids.add(h["id"])
                kinds[h.get("kind")] = kinds.get(h.get("kind"), 0) + 1
            for al in h.get("alarms", []):
                if (h["id"], al) not in raised:
                    raised.add((h["id"], al))
                    alarms.append((x["sweep"], h["id"], al, h.get("kind"), round(h["x_m"], 1), round(h["y_m"], 1)))
    n = max(1, len(sel))
    print(f"{a.label}{len(sel)} sweeps: confirmed tracks a sweep other than static since start {other / n:.2f} "
          f"({len(ids)} IDs; kinds {dict(sorted(kinds.items(), key=str))}), static since start {static / n:.2f}, "
          f"alarms {len(alarms)}" + "".join(f"; sweep {s} track {i} {al} ({k}) at {px}, {py}" for s, i, al, k, px, py in alarms[:6]))
    bad = []
    if a.max_tracks is not None and other / n > a.max_tracks:
        bad.append(f"{other / n:.2f} tracks a sweep > {a.max_tracks}")
    if a.max_alarms is not None and len(alarms) > a.max_alarms:
        bad.append(f"{len(alarms)} alarms > {a.max_alarms}")
    if bad:
        print(f"{a.label}FAILED: " + "; ".join(bad))
        sys.exit(1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    m = sub.add_parser("make")
    m.add_argument("csv")
    m.add_argument("truth")
    m.add_argument("--out", required=True, help="writes OUT.csv and OUT.truth.json")
    m.add_argument("--widen-gradians", type=float, default=6.0)
    m.add_argument("--widen-m", type=float, default=0.5)
    c = sub.add_parser("count")
    c.add_argument("jsonl")
    c.add_argument("--sweeps", help="A:B, the sweeps counted (default all)")
    c.add_argument("--max-tracks", type=float)
    c.add_argument("--max-alarms", type=int)
    c.add_argument("--label", default="")
    a = ap.parse_args()
    make(a) if a.cmd == "make" else count(a)


if __name__ == "__main__":
    main()
