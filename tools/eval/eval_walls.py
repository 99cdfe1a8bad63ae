"""eval_walls.py -- section 13 of docs/results.md (issue 52): the tracker at the site's walls. The moving pool scenes with a
survey of their empty site (20 and 40 looks an angle), the survey's lines as walls (`--track-walls on`, the default) and
without them (`--track-walls off`): MOTA, IDF1 and ID switches, and how many of the switches came at a wall; AquaScan
sonar4's swimmer 4 under the occupied-pool preset (which takes no survey, so no walls), and its far swimmer (person 5:
far_swimmer.py's contrasts, and the preset's variants that find it more often); the cost. Called by eval.py, or:

  .venv/bin/python tools/eval/eval_walls.py --build build [--real ../shared/data/real] [--work build/eval]

stdlib only (far_swimmer.py, run as a child, needs the evaluation venv's numpy and scipy). sonar11 is held out: run and
shown like the others, never tuned on.
"""
import json
import math
import os
import re
import sys

from eval_survey import _tracks

HERE = os.path.dirname(os.path.abspath(__file__))
SCORE = (sys.executable, os.path.join(HERE, "score.py"))
# scene, passes a survey of 20 looks takes (a sector whose step does not divide it looks at each angle every other pass)
SCENES = (("lanes", 2), ("laps", 1), ("turns", 2), ("occupied", 2), ("activity", 1))
WALL_M = 2.0  # a change of track within this of a wall is one at the wall (the swimmers turn 0.5 m out)


def _seg_d(px, py, w):
    x0, y0, x1, y1 = w
    ux, uy = x1 - x0, y1 - y0
    f = max(0.0, min(1.0, ((px - x0) * ux + (py - y0) * uy) / (ux * ux + uy * uy)))
    return math.hypot(px - x0 - f * ux, py - y0 - f * uy)


def _switches_at_walls(truth, out):
    """(switches, of them within WALL_M of a wall): a person's nearest confirmed track (1 m) changing ID."""
    t = json.load(open(truth))
    walls = t.get("walls", [])
    lines = [json.loads(x) for x in open(out)]
    last, n, at = {}, 0, 0
    for s, d in zip(t["sweeps"], lines):
        for o in s["objects"]:
            near = [(math.hypot(h["x_m"] - o["x"], h["y_m"] - o["y"]), h["id"]) for h in d["tracks"]
                    if h.get("state") != "tentative"]
            near = [x for x in near if x[0] <= 1.0]
            if not near:
                continue
            tid = min(near)[1]
            if o["id"] in last and last[o["id"]] != tid:
                n += 1
                at += any(_seg_d(o["x"], o["y"], w) <= WALL_M for w in walls)
            last[o["id"]] = tid
    return n, at


def _found(truth, out, pid):
    """(sweeps a labelled person was found in: a detection within 1 m, sweeps it was labelled)."""
    t = {s["sweep"]: s for s in json.load(open(truth))["sweeps"]}
    found = seen = 0
    for line in open(out):
        d = json.loads(line)
        o = [o for o in (t[d["sweep"]]["objects"] if d["sweep"] in t else []) if str(o["id"]) == pid]
        if o:
            seen += 1
            found += any(math.hypot(q["x_m"] - o[0]["x"], q["y_m"] - o[0]["y"]) < 1.0 for q in d["detections"])
    return found, seen


def _far_swimmer(sh, B, W):
    """Person 5 of sonar4 (a swimmer 9-10 m out) under the preset: why it is seldom found, and what finding it costs."""
    truth, rec, pid = f"{W}/aq/sonar4.truth.json", f"{W}/aq/sonar4.csv", "5"
    base = ["--replay", rec, "--json", "--quiet", "--log-level", "error", "--range", "15", "--config",
            "docs/presets/occupied-pool.conf"]
    runs = []
    for name, extra in (("the preset", []), ("its threshold at K 2.5 (3)", ["--threshold", "2.5"]),
                        ("the CFAR for its global threshold", ["--threshold-mode", "cfar"]),
                        ("0.15 m² for its 40 cells", ["--min-points", "12", "--min-area", "0.15"])):
        out = f"{W}/w_far{len(runs)}.jsonl"
        open(out, "w").write(sh([f"{B}/sonard"] + base + extra))
        score = sh([*SCORE, truth, out, "--tracks"])
        f1 = float(re.search(r"\bF1 ([0-9.]+)", score).group(1))
        idf1 = float(re.search(r"IDF1 ([0-9.]+)", score).group(1))
        runs.append((name, f1, idf1, *_found(truth, out, pid)))
    try:
        d = json.loads(sh([sys.executable, os.path.join(HERE, "far_swimmer.py"), rec, truth, f"{W}/w_far0.jsonl",
                           "--person", pid]))
    except Exception as e:  # numpy and scipy are the evaluation venv's: say so rather than fail the section
        return [f"(The far swimmer's contrast was not measured: {str(e).splitlines()[-1] if str(e) else e}; run with the "
                f"evaluation's venv, `.venv/bin/python`.)", ""]
    L = [f"**The far swimmer** (sonar4's person {pid}, {d['range_m'][0]}-{d['range_m'][1]} m out; "
         f"`tools/eval/far_swimmer.py` recomputes each sweep's foreground as the preset makes it): the preset finds it in "
         f"{runs[0][3]} of {runs[0][4]} labelled sweeps. Within 0.5 m of it, {d['track_points']} cells stand above the "
         f"sweep's threshold in {d['enough_for_a_track']} sweeps and {d['min_points']} in {d['enough_for_a_birth']}; its "
         f"{d['min_points']}th strongest cell stands {d['kth_median']:g} grey levels above the range background (median), "
         f"under the threshold's {d['threshold_median']:g}, where the four people nearer stand {d['others_kth_median']:g}. "
         f"Its echo is a beam or two wide at that range and under the water's own spread: the preset cannot take it "
         f"without taking the water (F1, IDF1 and the swimmer's sweeps found, sonar4):", ""]
    L += [f"- {name}: F1 {f1:.3f}, IDF1 {idf1:.3f}, found in {fo} of {se}" for name, f1, idf1, fo, se in runs]
    return L + [""]


def _person_tracks(truth, out, pid):
    """Distinct track IDs that were a labelled person's nearest (1 m), and the sweeps it was labelled."""
    t = {s["sweep"]: s for s in json.load(open(truth))["sweeps"]}
    ids, seen = [], 0
    for line in open(out):
        d = json.loads(line)
        s = t.get(d["sweep"])
        o = [o for o in (s["objects"] if s else []) if o["id"] == pid]
        if not o:
            continue
        seen += 1
        near = sorted((math.hypot(h["x_m"] - o[0]["x"], h["y_m"] - o[0]["y"]), h["id"]) for h in d["tracks"]
                      if h.get("state") != "tentative")
        if near and near[0][0] <= 1.0 and near[0][1] not in ids:
            ids.append(near[0][1])
    return ids, seen


def section(sh, run, B, W, have_real, cost):
    L = ["## 13. The tracker at the site's walls (issue 52)\n",
         "Where a survey is in use, its lines (places of kind structure: walls and lane ropes alike) are the tracker's "
         "walls: a model whose straight prediction would cross one, from the sonar's side, also predicts the turn "
         "there (reflected about the line 0.5 m out from it, where a swimmer's centre turns; at a corner twice), and a "
         "detection is judged against whichever of the two lies nearer (`src/core/tracker_walls.c`, docs/decisions.md). "
         "Each moving pool scene with a survey of its empty site (`sonar-sim --empty --seed 5`, 20 and 40 looks an "
         "angle), scored by `score.py --tracks` with the walls (`--track-walls on`, the default) and without: MOTA / "
         "IDF1 (ID switches; of the changes of a person's nearest confirmed track, those within 2 m of a wall). *turns*: four swimmers doing 25 m and 5 m lengths turned "
         "at the end walls, at 0.3-1.5 m/s, seen by a sector scanned back and forth (a place every 3.9-7.7 s); "
         "*occupied* and *activity*, the other pools with a swimmer, whose lengths end short of their walls. "
         "Without a survey there are no walls and every output is as before (the golden outputs are unchanged).\n",
         "| scene | survey | walls off: MOTA / IDF1 (switches; track changes at a wall, of all) | walls on |", "|---|---:|---|---|"]
    for sc, mult in SCENES:
        sh([f"{B}/sonar-sim", "--scene", sc, "--out", f"{W}/w_{sc}.csv", "--truth", f"{W}/w_{sc}.json"])
        for looks in (20, 40):
            e, sv = f"{W}/w_{sc}_{looks}_e.csv", f"{W}/w_{sc}.{looks}.survey"
            sh([f"{B}/sonar-sim", "--scene", sc, "--empty", "--seed", "5", "--sweeps", str(looks * mult), "--out", e,
                "--truth", os.devnull])
            if os.path.exists(sv):
                os.remove(sv)
            _, err, rc = run([f"{B}/sonard", "--replay", e, "--quiet", "--survey", str(looks * mult), "--survey", sv])
            if rc != 0:
                raise RuntimeError(f"{sc}: the survey of its empty site was refused: {err}")
            cells = []
            for walls in ("off", "on"):
                out = f"{W}/w_{sc}.{looks}.{walls}.jsonl"
                open(out, "w").write(sh([f"{B}/sonard", "--replay", f"{W}/w_{sc}.csv", "--json", "--quiet", "--log-level",
                                         "error", "--survey", sv, "--track-walls", walls]))
                mota, idf1, idsw = _tracks(sh, SCORE, f"{W}/w_{sc}.json", out)
                n, at = _switches_at_walls(f"{W}/w_{sc}.json", out)
                cells.append(f"{mota:.3f} / **{idf1:.3f}** ({idsw}; {at} of {n})")
            L.append(f"| {sc} | {looks} | " + " | ".join(cells) + " |")
    L.append("")
    if have_real:
        rows = []
        for rec, pid in (("sonar4", "4"), ("sonar11", None)):
            out = f"{W}/w_{rec}.preset.jsonl"
            open(out, "w").write(sh([f"{B}/sonard", "--replay", f"{W}/aq/{rec}.csv", "--json", "--quiet", "--log-level",
                                     "error", "--range", "15", "--config", "docs/presets/occupied-pool.conf"]))
            mota, idf1, idsw = _tracks(sh, SCORE, f"{W}/aq/{rec}.truth.json", out)
            who = ""
            if pid:
                ids, seen = _person_tracks(f"{W}/aq/{rec}.truth.json", out, pid)
                who = f"; swimmer {pid}: {len(ids)} tracks over its {seen} labelled sweeps"
            rows.append(f"- AquaScan {rec}" + (" (held out)" if rec == "sonar11" else "") + f", occupied-pool preset: "
                        f"MOTA {mota:.3f}, IDF1 {idf1:.3f}, {idsw} ID switches{who}.")
        L += ["**AquaScan** (15 m): the preset keeps the range background, which takes no survey, so the tracker has "
              "no walls there and the figures are those before issue 52:\n"] + rows + [""]
        L += _far_swimmer(sh, B, W)
    if cost.get("tracker_walls_sweep_us") and cost.get("tracker_sweep_us"):
        a, b = float(cost["tracker_sweep_us"]), float(cost["tracker_walls_sweep_us"])
        m7 = ""
        if cost.get("m7_insn_tracker_walls_sweep") and cost.get("m7_insn_tracker_sweep"):
            c, d = int(cost["m7_insn_tracker_sweep"]), int(cost["m7_insn_tracker_walls_sweep"])
            m7 = f"; on the Cortex-M7 (`make mcu-bench`) {c:,} and {d:,} instructions ({d / c:.2f}×)".replace(",", " ")
        L.append(f"Cost (`make bench`, this run): the tracker bench's sweep (32 tracks, 16 detections) {a:.1f} µs without "
                 f"walls, as before; with 16 walls about it (`tools/bench/tracker_scene.h`: nested boxes, the innermost "
                 f"reached by four tracks) {b:.1f} µs ({b / a:.2f}×){m7}. Each track finds the walls within its models' "
                 f"reach once an update (their boxes against its paths' box); a pair's prediction looks at those "
                 f"alone.\n")
    return L


if __name__ == "__main__":
    import standalone
    standalone.main(__doc__, section)
