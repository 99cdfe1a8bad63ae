#!/usr/bin/env python3
"""eval_tank.py -- section 14 of docs/results.md (issue 54): walls, their echoes and interference in one look. The
RoboSub robots' real sweeps (../shared/data/real/duke: one session of 63 sweeps replayed as it came, each of Oogway's
single sweeps alone, its seven +-30 degree sweeps together), objects a sweep by kind and a figure of every sweep with
its hulls; the simulated tank (sonar-sim --scene tank: a moving robot, walls with their echoes, streaks), objects F1
against its truth from the first look and each false object's cause; the scenes and recordings that must not lose.
Called by eval.py, or:

  .venv/bin/python tools/eval/eval_tank.py --build build [--real ../shared/data/real] [--work build/eval]
      [--docs docs] [--before OLD/sonard]

--before: a sonard of an earlier commit, run beside this one on the same inputs (its columns say "before"). The
evaluation venv's numpy and matplotlib draw the figures.
"""
import argparse
import collections
import glob
import gzip
import json
import math
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import score  # noqa: E402  (its greedy matching: one place)

SCORE = (sys.executable, os.path.join(HERE, "score.py"))
KINDS = ("object", "static since start", "structure", "wall echo")
DUKE_ARGS = ["--range", "5", "--angle-offset", "200"]  # PROVENANCE.md: 5 m, forward at 200 gradians
END = "at the range's end"


def _run(cmd, stdin=None):
    p = subprocess.run(cmd, input=stdin, capture_output=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))}: exit {p.returncode}: {p.stderr.decode()[-400:]}")
    return p.stdout.decode(), p.stderr.decode()


def _sweeps(out):
    return [json.loads(x) for x in out.splitlines() if x.startswith("{") and '"detections"' in x]


def _counted(err, what):
    m = re.search(r"(\d+) blank beams skipped, (\d+) beams left out as interference", err)
    return int(m.group(2 if what == "interference" else 1)) if m else 0


def _kinds(sweeps):
    k = collections.Counter()
    for s in sweeps:
        for d in s["detections"]:
            k[d.get("kind", "object")] += 1
    n = max(1, len(sweeps))
    return {x: k[x] / n for x in KINDS}


def _rows(data):
    rows = []
    for line in data.decode().splitlines():
        f = line.split(",", 3)
        if len(f) == 4 and f[0][:1].isdigit():
            rows.append((int(f[2]), [int(t) for t in f[3].strip().strip('"').split()]))
    return rows


def _figure(path, rows, sweeps, per, cols, title):
    """Every sweep of a file (per: beams a sweep, as sonard cut them) with its hulls, one panel each."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    sys.path.insert(0, HERE)
    import figures
    n = len(sweeps)
    nr = (n + cols - 1) // cols
    fig, axs = plt.subplots(nr, cols, figsize=(2.6 * cols, 2.6 * nr), squeeze=False)
    at = 0
    for k in range(nr * cols):
        ax = axs[k // cols][k % cols]
        if k >= n:
            ax.axis("off")
            continue
        b = sweeps[k]["beams"] if "beams" in sweeps[k] else per
        part = rows[at:at + b]
        at += b
        kinds = collections.Counter(d.get("kind", "object") for d in sweeps[k]["detections"])
        figures.fan(ax, np.array([v for _, v in part]), [a for a, _ in part], 5.0,
                    f"{k + 1}: {kinds['object'] + kinds['static since start']} obj, {kinds['structure']} wall, "
                    f"{kinds['wall echo']} echo", sweeps[k], 200.0)
    fig.suptitle(title + " (objects green, static since start white, walls cyan, walls' echoes blue)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=70)
    plt.close(fig)


def real_sweeps(B, real, docs, before):
    D = os.path.join(real, "duke")
    files = [("session 2024, 63 sweeps as they came", os.path.join(D, "session-2024-63sweeps.csv.gz"), "duke_session.png", 9)]
    files += [(f"Oogway {os.path.basename(f)[6:-7]} alone", f, None, 1)
              for f in sorted(glob.glob(os.path.join(D, "oogway-2025-10-25", "sweep_*.csv.gz")))]
    files.append(("Oogway's seven +-30 degree sweeps together", os.path.join(D, "oogway-2025-10-25", "oogway_pm30_x7.csv.gz"),
                  "duke_oogway_pm30.png", 7))
    L = ["| recording | sweeps | objects a sweep | static since start | walls | walls' echoes | interference beams |" +
         (" before: objects (static) |" if before else ""),
         "|---|---:|---:|---:|---:|---:|---:|" + ("---:|" if before else "")]
    singles, figs = [], []
    total = collections.Counter()
    for label, path, fig, cols in files:
        data = gzip.open(path).read()
        out, err = _run([f"{B}/sonard", "--replay", "-", "--json"] + DUKE_ARGS, data)
        sw = _sweeps(out)
        k = _kinds(sw)
        row = f"| {label} | {len(sw)} | {k['object']:.2f} | {k['static since start']:.2f} | {k['structure']:.2f} | " \
              f"{k['wall echo']:.2f} | {_counted(err, 'interference')} |"
        if before:
            kb = _kinds(_sweeps(_run([before, "--replay", "-", "--json"] + DUKE_ARGS, data)[0]))
            row += f" {kb['object'] + kb['static since start']:.2f} ({kb['static since start']:.2f}) |"
        if fig:
            L.append(row)
            figs.append((fig, label))
            _figure(os.path.join(docs, "figures", fig), _rows(data), sw, 101, cols, label)
        else:
            singles.append((sw, _rows(data)))
            L.append(row)
        if label.startswith("session"):
            total.update({"session": k["object"] + k["static since start"]})
    if singles:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np
        sys.path.insert(0, HERE)
        import figures
        fig, axs = plt.subplots(2, 4, figsize=(11, 5.5), squeeze=False)
        for i, (sw, rows) in enumerate(singles[:8]):
            ax = axs[i // 4][i % 4]
            kinds = collections.Counter(d.get("kind", "object") for d in sw[0]["detections"]) if sw else {}
            figures.fan(ax, np.array([v for _, v in rows]), [a for a, _ in rows], 5.0,
                        f"sweep {i + 1}: {kinds.get('object', 0)} obj, {kinds.get('structure', 0)} wall, "
                        f"{kinds.get('wall echo', 0)} echo", sw[0] if sw else None, 200.0)
        fig.suptitle("Oogway's single sweeps, each alone", fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(docs, "figures", "duke_oogway_single.png"), dpi=70)
        plt.close(fig)
        figs.append(("duke_oogway_single.png", "Oogway's single sweeps"))
    return L, figs


def _pose_at(pose, t_us):
    """(north, east, yaw_deg) of the vehicle at t_us, from sonar-sim's --pose-out rows (nearest)."""
    lo, hi = 0, len(pose) - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if pose[mid][0] < t_us:
            lo = mid + 1
        else:
            hi = mid
    return pose[lo][1:]


def _seg(px, py, w):
    x0, y0, x1, y1 = w
    ux, uy = x1 - x0, y1 - y0
    f = max(0.0, min(1.0, ((px - x0) * ux + (py - y0) * uy) / (ux * ux + uy * uy)))
    return math.hypot(px - x0 - f * ux, py - y0 - f * uy)


def _inside(px, py, walls):
    """Whether (north, east) lies inside the tank: walls as the truth gives them (an axis-aligned rectangle)."""
    xs = [v for w in walls for v in (w[0], w[2])]
    ys = [v for w in walls for v in (w[1], w[3])]
    return min(xs) < px < max(xs) and min(ys) < py < max(ys)


def tank(B, W, before):
    csv, truth, pose = f"{W}/tank.csv", f"{W}/tank.json", f"{W}/tank.pose.csv"
    _run([f"{B}/sonar-sim", "--scene", "tank", "--out", csv, "--truth", truth, "--pose-out", pose])
    T = json.load(open(truth))
    P = [tuple(map(float, x.split(","))) for x in open(pose).read().splitlines()[1:]]
    streaks = sum(len(s.get("streaks", [])) for s in T["sweeps"])
    res = {}
    for who, binary in (("after", f"{B}/sonard"),) + ((("before", before),) if before else ()):
        out, err = _run([binary, "--replay", csv, "--json"])
        path = f"{W}/tank.{who}.jsonl"
        open(path, "w").write(out)
        r, _ = _run(list(SCORE) + [truth, path])
        line = r.strip().splitlines()[-1]
        f1 = float(re.search(r"F1 (\S+)", line).group(1))
        # Each false object's cause: on a wall (within 0.3 m of one), beyond the tank's walls (an echo), else.
        cause = collections.Counter()
        for k, s in enumerate(_sweeps(out)):
            objs = [d for d in s["detections"] if d.get("kind", "object") not in ("structure", "wall echo")]
            tr = T["sweeps"][k]["objects"] if k < len(T["sweeps"]) else []
            used_d = {i for i, _, _ in score.pairs([(d["x_m"], d["y_m"]) for d in objs], [(t["bx"], t["by"]) for t in tr], 1.0)}
            for i, d in enumerate(objs):
                if i in used_d:
                    continue
                n, e, yaw = _pose_at(P, d["utime"])
                c, sn = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
                wn, we = n + d["x_m"] * c - d["y_m"] * sn, e + d["x_m"] * sn + d["y_m"] * c
                if min(_seg(wn, we, w) for w in T["walls"]) <= 0.3:
                    cause["on a wall"] += 1
                elif not _inside(wn, we, T["walls"]):
                    cause["beyond a wall"] += 1
                elif d["range_m"] >= T["range_m"] - 0.15:
                    cause[END] += 1
                else:
                    cause["elsewhere"] += 1
        k = _kinds(_sweeps(out))
        res[who] = (line, f1, cause, _counted(err, "interference"), k)
    return res, streaks, len(T["sweeps"])


def no_loss(B, W, real):
    """(label, figure) rows: the near buoys, the moving vehicle's world frame, AquaScan under default and preset."""
    rows = []
    _run([f"{B}/sonar-sim", "--scene", "near", "--out", f"{W}/t_near.csv", "--truth", f"{W}/t_near.json"])
    out, _ = _run([f"{B}/sonard", "--replay", f"{W}/t_near.csv", "--json"])
    open(f"{W}/t_near.jsonl", "w").write(out)
    r, _ = _run(list(SCORE) + [f"{W}/t_near.json", f"{W}/t_near.jsonl"])
    rows.append(("near: three 0.2 m buoys at 0.66-1.2 m, 5 m range (default)", r.strip().splitlines()[-1]))
    _run([f"{B}/sonar-sim", "--scene", "vehicle", "--out", f"{W}/t_veh.csv", "--truth", f"{W}/t_veh.json",
          "--pose-out", f"{W}/t_veh.pose.csv"])
    out, _ = _run([f"{B}/sonard", "--replay", f"{W}/t_veh.csv", "--json", "--min-points", "8", "--pose",
                   f"{W}/t_veh.pose.csv"])
    open(f"{W}/t_veh.jsonl", "w").write(out)
    r, _ = _run(list(SCORE) + [f"{W}/t_veh.json", f"{W}/t_veh.jsonl", "--frame", "world"])
    rows.append(("vehicle: world frame (`--min-points 8 --pose`)", r.strip().splitlines()[-1]))
    aq = os.path.join(real, "aquascan")
    if os.path.isdir(aq):
        _run([sys.executable, os.path.join(HERE, "..", "data", "aquascan2csv.py"), aq, "--out", f"{W}/t_aq", "--range", "15"])
        preset = os.path.join(HERE, "..", "..", "docs", "presets", "occupied-pool.conf")
        for rec in ("sonar4", "sonar11"):
            for label, extra in (("default", []), ("occupied-pool preset", ["--config", preset])):
                out, _ = _run([f"{B}/sonard", "--replay", f"{W}/t_aq/{rec}.csv", "--json", "--quiet"] + extra)
                path = f"{W}/t_aq_{rec}_{label[:3]}.jsonl"
                open(path, "w").write(out)
                det, _ = _run(list(SCORE) + [f"{W}/t_aq/{rec}.truth.json", path])
                trk, _ = _run(list(SCORE) + [f"{W}/t_aq/{rec}.truth.json", path, "--tracks"])
                idf1 = re.search(r"IDF1 (\S+)", trk)
                rows.append((f"AquaScan {rec}{' (held out)' if rec == 'sonar11' else ''}, {label}",
                             det.strip().splitlines()[-1] + (f"; tracks IDF1 {idf1.group(1)}" if idf1 else "")))
    return rows


def section(sh, B, W, have_real, real, docs, before=None):
    L = ["## 14. Walls, their echoes and interference in one look (issue 54)\n",
         "A vehicle's sonar often looks at a place once. In that single look sonard now tells apart, beside the objects "
         "(`src/core/detector_accept.c`, `detector_edge.c`, `detector_wall.c`, `detector_echo.c`, `streak.c`, `edge.c`; "
         "docs/decisions.md, \"Walls, their echoes and streaks in one look\" and \"The water's boundary\"): **walls** "
         "(kind structure): a line at least 0.6 m long, at most 0.25 m thick and 4 times longer than thick; longer "
         "than 1.5 m, 6.5 times longer than thick (an oblique wall) or thin on every beam (a corner); thin pieces "
         "continuing one another or a wall within 0.5 m; or **the water's boundary**: a cluster holding its beams' "
         "leading edge (their first echo half as strong as their strongest), no deeper on a beam than a line plus "
         "what the edge's range changes across the beam, beside which the edge runs on 0.6 m (within 0.15 m of its "
         "slope, half as strong, behind something nearer up to 1 m across) or which the sector's end cuts. **A wall's "
         "echo** (kind `wall echo`): three quarters of its cells beyond the nearest wall on the same beams (or two "
         "beams aside) and weaker than that wall. **Interference**: a beam standing above the background along three "
         "quarters of its length and twice the share of the ordinary beam before it, a neighbour: left out of the "
         "background and the detector, counted on SONAR_STATUS `interference_beams`. **Blank beams** (every sample 0 "
         "or 255) are skipped, said and counted (`blank_beams`). Where the beams overlap (a step of at most half the "
         "beam's width) **a cluster on one beam** is a fragment, not an object.\n"]
    if have_real and os.path.isdir(os.path.join(real, "duke")):
        L.append("**The RoboSub sweeps** (../shared/data/real/duke, tuning; default options as a new user runs them, "
                 "`zcat F | sonard --replay - --json --range 5 --angle-offset 200`): detections a sweep by kind. No "
                 "truth is labelled; the figures show every sweep with its hulls.\n")
        rows, figs = real_sweeps(B, real, docs, before)
        L += rows
        L.append("")
        for f, label in figs:
            L.append(f"![{label}](figures/{f})")
        L.append("")
    else:
        L.append("*The RoboSub sweeps: ../shared/data/real/duke is absent here.*\n")
    res, streaks, nsw = tank(B, W, before)
    session = os.path.join(real, "duke", "session-2024-63sweeps.csv.gz")
    if have_real and os.path.exists(session):
        cal, _ = _run([sys.executable, os.path.join(HERE, "tank_calib.py"), session])
        L.append("The tank's acoustics on the RoboSub session (`tools/eval/tank_calib.py`), which the simulated tank "
                 "draws (tools/sim/scene.c):\n")
        L += [f"- {x}" for x in cal.strip().splitlines()]
        L.append("")
    L.append(f"**The simulated tank** (`sonar-sim --scene tank`, {nsw} sweeps: a robot crossing an 8 x 5 m tank at "
             "0.1 m/s while its heading swings +-30 degrees, a +-45 degree sector at 1 gradian, 5 m range; three props; "
             "the walls' echoes at twice and three times their range and the streaks as measured above). Objects "
             "scored from the first look by `score.py` (1 m gate; walls and walls' echoes are not objects); each false "
             "object's cause from the truth's walls and the vehicle's pose.\n")
    L.append("| sonard | objects: precision / recall / F1 (TP FP FN) | false objects on a wall / beyond one / at the "
             "range's end / elsewhere | walls' echoes a sweep | streaked beams: drawn / left out |")
    L.append("|---|---|---|---:|---|")
    for who in ("before", "after"):
        if who not in res:
            continue
        line, f1, cause, inter, k = res[who]
        m = re.search(r"precision (\S+)\s+recall (\S+)\s+F1 (\S+).*\(TP (\d+) FP (\d+) FN (\d+)", line)
        L.append(f"| {who} | {m.group(1)} / {m.group(2)} / {m.group(3)} ({m.group(4)} {m.group(5)} {m.group(6)}) | "
                 f"{cause['on a wall']} / {cause['beyond a wall']} / {cause[END]} / {cause['elsewhere']} | "
                 f"{k['wall echo']:.2f} | {streaks} / {inter} |")
    L.append("")
    L.append("**No loss elsewhere** (`score.py`, 1 m gate):\n")
    L.append("| input | detections |")
    L.append("|---|---|")
    for label, line in no_loss(B, W, real if have_real else ""):
        L.append(f"| {label} | {line} |")
    L.append("")
    return L


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--real", default=os.path.join(HERE, "..", "..", "..", "shared", "data", "real"))
    ap.add_argument("--work", default="build/eval")
    ap.add_argument("--docs", default="docs")
    ap.add_argument("--before", default=None)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    os.makedirs(os.path.join(a.docs, "figures"), exist_ok=True)
    print("\n".join(section(None, a.build, a.work, os.path.isdir(a.real), a.real, a.docs, a.before)))


if __name__ == "__main__":
    main()
