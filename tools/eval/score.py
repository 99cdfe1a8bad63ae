#!/usr/bin/env python3
"""score.py -- scores sonard --json detections against a simulator truth file (stdlib only).

A detection is a true positive when its centroid lies within --gate metres of a not yet matched
truth object of the same sweep (closest pairs first); other detections are false positives (but
one within the gate of a "hidden" object, below, is don't-care), unmatched objects false
negatives. Sweeps marked "labelled": false (no label file) are skipped. Prints precision, recall,
F1, centroid error and false alarms per sweep; with --min-precision/--min-recall/--min-f1/
--max-error it exits 1 when a target is missed. --object ID,... lists the sweeps each of those
truth objects was found in (--still: only those where it stands still), --min-found a floor on it.

With --tracks it also scores the "tracks" of each line (confirmed and coasting ones, or those of
--states; each predicted to the time its truth object was seen, "t_us", when the truth has it)
against the truth IDs: MOTA (CLEAR MOT: a match kept while it stays within the gate, the rest
assigned at least total distance), IDF1 (one global truth-ID to track-ID assignment), ID switches
(also per 100 track-sweeps), fragmentations, OSPA (cut-off 2 m, p = 2, mean over sweeps) and the
mean velocity error of matched tracks with 3+ hits on objects moving at 0.5..1.5 m/s, and their mean
speed on objects that stand still (static speed, --max-static-speed), and the ceilings on MOTA and
IDF1 of any tracker that confirms a track on its second hit (each object's first sighting is then a
miss). --min-idf1, --min-mota, --max-idsw-per-100 and --max-vel-error then also decide the exit
status. A track left unmatched within the gate of a "hidden" truth object (there but unseen that
sweep: faded, or no beam crossed it) is don't-care, as MOTChallenge treats ignored regions: not a
false positive, not counted.

--frame picks the frame scored when the sonar moves (truth with "bx", "by"): body (default) compares
the sonar-frame positions (x_m, y_m) with the truth's bx, by, and leaves velocity out; world compares
north_m, east_m (and vn_mps, ve_mps) with the truth's x, y, vx, vy; a detection or track without them
(no pose then) cannot match.
"""
import argparse
import json
import math
import sys


def pairs(a, b, gate):
    """Greedy closest pairs first between points a and b ((x, y) each) within gate metres: [(i, j, distance)]."""
    out, used_a, used_b = [], set(), set()
    for dist, i, j in sorted((math.hypot(p[0] - q[0], p[1] - q[1]), i, j) for i, p in enumerate(a) for j, q in enumerate(b)):
        if dist > gate or i in used_a or j in used_b:
            continue
        used_a.add(i)
        used_b.add(j)
        out.append((i, j, dist))
    return out


def match(dets, objs, gate):
    got = pairs([(d["x_m"], d["y_m"]) for d in dets], [(o["x"], o["y"]) for o in objs], gate)
    errs = [dist for _, _, dist in got]
    return len(errs), len(dets) - len(errs), len(objs) - len(errs), errs, {i for i, _, _ in got}, {j for _, j, _ in got}


def ignored(dets, used, hidden, gate):
    """Detections left unmatched within the gate of an object that is there but unseen this sweep
    by the simulator's schedule (faded, or no beam crossed it): don't-care, as for tracks. Live, the
    beams' times follow the machine's clock, so a beam can cross an object the schedule says none did."""
    n = 0
    for i, d in enumerate(dets):
        if i not in used and any(math.hypot(d["x_m"] - o["x"], d["y_m"] - o["y"]) <= gate for o in hidden):
            n += 1
    return n


def assign(cost):
    """Least-total assignment of the rows of cost (rows <= cols) to distinct columns: row -> column."""
    n, m = len(cost), len(cost[0]) if cost else 0
    if n == 0:
        return []
    if n > m:
        t = assign([list(r) for r in zip(*cost)])
        out = [-1] * n
        for j, i in enumerate(t):
            out[i] = j
        return out
    inf = float("inf")
    u, v, p, way = [0.0] * (n + 1), [0.0] * (m + 1), [0] * (m + 1), [0] * (m + 1)
    for i in range(1, n + 1):
        p[0], j0 = i, 0
        minv, used = [inf] * (m + 1), [False] * (m + 1)
        while True:
            used[j0] = True
            i0, delta, j1 = p[j0], inf, 0
            for j in range(1, m + 1):
                if not used[j]:
                    cur = cost[i0 - 1][j - 1] - u[i0] - v[j]
                    if cur < minv[j]:
                        minv[j], way[j] = cur, j0
                    if minv[j] < delta:
                        delta, j1 = minv[j], j
            for j in range(m + 1):
                if used[j]:
                    u[p[j]] += delta
                    v[j] -= delta
                else:
                    minv[j] -= delta
            j0 = j1
            if p[j0] == 0:
                break
        while j0:
            j1 = way[j0]
            p[j0] = p[j1]
            j0 = j1
    out = [-1] * n
    for j in range(1, m + 1):
        if p[j]:
            out[p[j] - 1] = j - 1
    return out


def track_at(h, o):
    """Track h's position at the time truth object o was seen (its own state when o has no time)."""
    dt = (o["t_us"] - h["utime"]) * 1e-6 if "t_us" in o and "utime" in h else 0.0
    return h["x_m"] + h["vx_mps"] * dt, h["y_m"] + h["vy_mps"] * dt


def pair_dist(h, o):
    """Metres between track h and truth object o: at o's time, or, when o can say where it was at any time
    ("pos_at": utime -> (x, y)), at the time of h's own state."""
    if "pos_at" in o and "utime" in h:
        tx, ty = o["pos_at"](h["utime"])
        return math.hypot(h["x_m"] - tx, h["y_m"] - ty)
    return math.hypot(*(a - b for a, b in zip(track_at(h, o), (o["x"], o["y"]))))


def score_tracks(truth, lines, gate, cutoff=2.0, p=2, hidden=None, states=("confirmed", "coasting")):
    hidden = hidden or {}
    gt = fp = fn = idsw = frag = tp = hyp_total = 0
    last = {}          # truth id -> track id it was last matched to
    was_matched = {}   # truth id -> matched in its previous present sweep
    ever, present = set(), set()
    ospa, verr, still = [], [], []
    pair_count = {}    # (truth id, track id) -> sweeps within the gate, for IDF1
    truth_total = 0
    for k in sorted(truth):
        objs = truth[k]
        hyps = [h for h in lines.get(k, {}).get("tracks", []) if h["state"] in states]
        gt += len(objs)
        truth_total += len(objs)
        present.update(o["id"] for o in objs)
        hyp_total += len(hyps)
        dist = [[pair_dist(h, o) for h in hyps] for o in objs]
        for i, o in enumerate(objs):
            for j, h in enumerate(hyps):
                if dist[i][j] <= gate:
                    pair_count[(o["id"], h["id"])] = pair_count.get((o["id"], h["id"]), 0) + 1
        # CLEAR MOT: keep last sweep's pairs still within the gate, assign the rest
        match, used_h = {}, set()
        for i, o in enumerate(objs):
            if o["id"] in last:
                for j, h in enumerate(hyps):
                    if h["id"] == last[o["id"]] and dist[i][j] <= gate and j not in used_h:
                        match[i] = j
                        used_h.add(j)
        ri = [i for i in range(len(objs)) if i not in match]
        cj = [j for j in range(len(hyps)) if j not in used_h]
        if ri and cj:
            big = 1e6
            sol = assign([[dist[i][j] if dist[i][j] <= gate else big for j in cj] for i in ri])
            for a, b in enumerate(sol):
                if b >= 0 and dist[ri[a]][cj[b]] <= gate:
                    match[ri[a]] = cj[b]
        for i, o in enumerate(objs):
            oid = o["id"]
            if i in match:
                h = hyps[match[i]]
                tp += 1
                if oid in last and last[oid] != h["id"]:
                    idsw += 1
                if oid in ever and not was_matched.get(oid, True):
                    frag += 1
                last[oid] = h["id"]
                ever.add(oid)
                was_matched[oid] = True
                sp = math.hypot(o.get("vx", 0.0), o.get("vy", 0.0))
                if 0.5 <= sp <= 1.5 and h.get("hits", 0) >= 3 and "vx" in o:
                    verr.append(math.hypot(h["vx_mps"] - o["vx"], h["vy_mps"] - o["vy"]))
                if "vx" in o and sp < 0.05 and h.get("hits", 0) >= 3:
                    still.append(math.hypot(h["vx_mps"], h["vy_mps"]))
            else:
                fn += 1
                was_matched[oid] = False
        # Don't-care: an unmatched track within the gate of an object that is there but unseen this
        # sweep (faded, or no beam crossed it) is coasting on something real: neither TP nor FP.
        dc, taken = set(), set(match.values())
        for o in hidden.get(k, []):
            for j, h in enumerate(hyps):
                if j not in taken and j not in dc and \
                        pair_dist(h, o) <= gate:
                    dc.add(j)
                    break
        hyp_total -= len(dc)
        fp += len(hyps) - len(match) - len(dc)
        # OSPA between the truth and the tracks of this sweep
        keep = [j for j in range(len(hyps)) if j not in dc]
        n, m = len(objs), len(keep)
        if n == 0 and m == 0:
            ospa.append(0.0)
        elif n == 0 or m == 0:
            ospa.append(cutoff)
        else:
            cm = [[min(cutoff, dist[i][j]) ** p for j in keep] for i in range(n)]
            sol = assign(cm)
            total = sum(cm[i][sol[i]] for i in range(n) if sol[i] >= 0)
            ospa.append(((total + cutoff ** p * abs(n - m)) / max(n, m)) ** (1.0 / p))
    # IDF1: one truth id -> track id assignment over the whole run
    tids = sorted({a for a, _ in pair_count})
    hids = sorted({b for _, b in pair_count})
    idtp = 0
    if tids and hids:
        sol = assign([[-pair_count.get((t, h), 0) for h in hids] for t in tids])
        idtp = sum(pair_count.get((tids[i], hids[j]), 0) for i, j in enumerate(sol) if j >= 0)
    idf1 = 2 * idtp / (truth_total + hyp_total) if truth_total + hyp_total else 1.0
    mota = 1 - (fn + fp + idsw) / gt if gt else 1.0
    return {"mota": mota, "idf1": idf1, "idsw": idsw, "idsw_per_100": 100.0 * idsw / max(1, hyp_total),
            "frag": frag, "ospa": sum(ospa) / len(ospa) if ospa else 0.0,
            "vel_err": sum(verr) / len(verr) if verr else float("nan"), "vel_n": len(verr),
            "still": sum(still) / len(still) if still else float("nan"), "still_n": len(still),
            "tp": tp, "fp": fp, "fn": fn, "gt": gt, "track_sweeps": hyp_total,
            # A tracker that publishes a track once it has M hits misses at least each object's
            # first M - 1 sightings: with sonard's 2, MOTA cannot pass 1 - objects / object-sweeps.
            # IDF1 then has at most G - O true IDs among at least as many published, of G truths:
            # 2 (G - O) / (2 G - O), with no false track and no other miss.
            "objects": len(present), "mota_ceiling": 1 - len(present) / gt if gt else 1.0,
            "idf1_ceiling": 2 * (gt - len(present)) / (2 * gt - len(present)) if gt else 1.0}


def late(lines):
    """Each sweep's tracks as a consumer one sweep late reads them: the IDs the next sweep revised ("revisions":
    the track published as id is now; 0: withdrawn) relabelled."""
    out = {}
    for k, d in lines.items():
        nxt = lines.get(k + 1, {})
        now = {r["id"]: r["now"] for r in nxt.get("revisions", [])}
        d = dict(d)
        d["tracks"] = [dict(h, id=now.get(h["id"], h["id"])) for h in d.get("tracks", []) if now.get(h["id"], 1) != 0]
        out[k] = d
    return out


def revisions(lines):
    return sum(1 for d in lines.values() if d.get("revisions"))


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
    ap.add_argument("--object", help="truth IDs (comma-separated) whose sweeps found are listed: found in k of n")
    ap.add_argument("--still", action="store_true", help="with --object: only the sweeps where it stands still (vx = vy = 0)")
    ap.add_argument("--min-found", type=float, help="with --object: the least fraction of its sweeps each must be found in")
    ap.add_argument("--tracks", action="store_true", help="also score the tracks (MOTA, IDF1, OSPA, ...)")
    ap.add_argument("--states", default="confirmed,coasting",
                    help="the track states scored (default confirmed,coasting; confirmed alone: the tracks hit that sweep, "
                         "which OBSTACLE_DISTANCE_3D sends the autopilot)")
    ap.add_argument("--min-idf1", type=float)
    ap.add_argument("--min-mota", type=float)
    ap.add_argument("--max-idsw-per-100", type=float)
    ap.add_argument("--max-vel-error", type=float, help="m/s")
    ap.add_argument("--max-static-speed", type=float,
                    help="m/s: mean speed of matched tracks (3+ hits) on objects that stand still")
    ap.add_argument("--frame", choices=("body", "world"), default="body", help="frame to score a moving sonar in")
    ap.add_argument("--late", action="store_true",
                    help="score each sweep's tracks as read one sweep late: relabelled by the next sweep's revisions")
    ap.add_argument("--from-sweep", type=int, default=0,
                    help="score the sweeps from this one on (1: from the second, after a first look at the site)")
    ap.add_argument("--verbose", action="store_true")
    a = ap.parse_args()
    bad = [x for x in a.states.split(",") if x not in ("tentative", "confirmed", "coasting")]
    if bad:
        ap.error(f"--states: {bad[0]!r} is not tentative, confirmed or coasting")
    # sweeps marked "labelled": false have unknown truth: neither their detections nor their objects count
    tj = json.load(open(a.truth))["sweeps"]
    truth = {s["sweep"]: s["objects"] for s in tj if s.get("labelled", True) and s["sweep"] >= a.from_sweep}
    hidden = {s["sweep"]: s.get("hidden", []) for s in tj if s.get("labelled", True) and s["sweep"] >= a.from_sweep}
    if a.frame == "body":
        # A moving sonar's truth: its own frame, where velocities over ground do not apply.
        for objs in list(truth.values()) + list(hidden.values()):
            for o in objs:
                if "bx" in o:
                    o["x"], o["y"] = o["bx"], o["by"]
                    o.pop("vx", None)
                    o.pop("vy", None)
    sweeps, lines = {}, {}
    for n, line in enumerate(open(a.detections), 1):
        line = line.strip()
        if not line:
            continue
        try:
            d = json.loads(line)
        except json.JSONDecodeError as e:
            sys.exit(f"{a.detections}:{n}: not JSON: {e}")
        if a.frame == "world":
            nan = float("nan")
            for o in d["detections"]:
                o["x_m"], o["y_m"] = o.get("north_m", nan), o.get("east_m", nan)
            for h in d.get("tracks", []):
                h["x_m"], h["y_m"] = h.get("north_m", nan), h.get("east_m", nan)
                h["vx_mps"], h["vy_mps"] = h.get("vn_mps", nan), h.get("ve_mps", nan)
        # Structure (a track that never moved, a wall) is reported as such, not as an object: not scored as one.
        sweeps[d["sweep"]] = [o for o in d["detections"] if o.get("kind", "object") not in ("structure", "wall echo")]
        lines[d["sweep"]] = d
    if a.late:
        lines = late(lines)
    tp = fp = fn = 0
    errs = []
    watch = {i: [] for i in (a.object.split(",") if a.object else [])}
    for k in sorted(truth):
        dets = sweeps.get(k, [])
        t, f, m, e, used, found = match(dets, truth[k], a.gate)
        f -= ignored(dets, used, hidden.get(k, []), a.gate)
        for j, o in enumerate(truth[k]):
            if str(o["id"]) in watch and (not a.still or (o.get("vx", 1.0) == 0.0 and o.get("vy", 1.0) == 0.0)):
                watch[str(o["id"])].append(j in found)
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
    for i, hits in watch.items():
        frac = sum(hits) / len(hits) if hits else float("nan")
        print(f"{a.label}object {i}: found in {sum(hits)} of {len(hits)} {'still ' if a.still else ''}sweeps "
              f"({frac:.3f}): {''.join('X' if h else '.' for h in hits)}")
        if a.min_found is not None and not (frac >= a.min_found):
            print(f"FAIL: object {i} found in {frac:.3f} of its sweeps < {a.min_found}")
            ok = False
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
    if a.tracks:
        t = score_tracks(truth, lines, a.gate, hidden=hidden, states=tuple(a.states.split(",")))
        print(f"{a.label}tracking: MOTA {t['mota']:.3f}  IDF1 {t['idf1']:.3f}  ID switches {t['idsw']} "
              f"({t['idsw_per_100']:.2f} per 100 track-sweeps)  revisions {revisions(lines)}  fragmentations {t['frag']}  OSPA {t['ospa']:.3f} m  "
              f"velocity error {t['vel_err']:.3f} m/s (n={t['vel_n']})  static speed {t['still']:.3f} m/s "
              f"(n={t['still_n']})  (TP {t['tp']} FP {t['fp']} FN {t['fn']}, "
              f"{t['track_sweeps']} track-sweeps; with 2 hits to confirm, ceilings MOTA {t['mota_ceiling']:.3f} "
              f"IDF1 {t['idf1_ceiling']:.3f}: {t['objects']} objects' first sightings)")
        for key, lim, worse in (("idf1", a.min_idf1, lambda v, l: v < l), ("mota", a.min_mota, lambda v, l: v < l),
                                ("idsw_per_100", a.max_idsw_per_100, lambda v, l: v > l),
                                ("vel_err", a.max_vel_error, lambda v, l: not (v <= l)),
                                ("still", a.max_static_speed, lambda v, l: not (v <= l))):
            if lim is not None and worse(t[key], lim):
                print(f"FAIL: {key} {t[key]:.3f} misses {lim}")
                ok = False
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
