"""eval_survey.py -- section 10 of docs/results.md (issue 43): the site survey (default against a survey, per scene), its
fit checks (a turned mount, another site), its refusals, the resolution floor, and its cost; called by eval.py.

The scenes' empty recordings are the same pools with nobody in them and another speckle seed (`sonar-sim --empty`);
nothing here was tuned on the held-out recording (AquaScan sonar11), which is run and shown like the others.
"""
import json
import os
import re

# Each pool scene, the sweeps of its empty recording that give 20 and 40 looks an angle (the lanes' 3-gradian sector,
# whose step does not divide it, looks at each angle every other pass), and who is watched.
SCENES = [("occupied", "occupied pool", 1, ["--object", "stand_a,stand_b"]),
          ("still", "still person", 1, ["--object", "floater,stand", "--still"]),
          ("lanes", "lanes (ropes, ladder, swimmers)", 2, ["--object", "rester", "--still"]),
          ("faint", "faint targets at 12-14 m", 1, ["--object", "faint_a,faint_b,faint_c"]),
          ("far", "far swimmers", 1, []),
          ("laps", "full-circle pool at 4 gradians", 1, [])]
TRACKED = ("lanes", "laps")


def _objects(path):
    """Objects (not structure) a sweep, and the sweeps."""
    n = sweeps = 0
    for line in open(path):
        d = json.loads(line)
        sweeps += 1
        n += sum(1 for o in d["detections"] if o.get("kind", "object") != "structure")
    return n, sweeps


def _tracks(sh, score_py, truth, out):
    r = sh([score_py[0], score_py[1], truth, out, "--tracks"])
    m = re.search(r"MOTA (\S+)\s+IDF1 (\S+)\s+ID switches (\d+)", r)
    return (float(m[1]), float(m[2]), int(m[3])) if m else None


def _fastest(truth):
    """The farthest any object of the truth went over 4 sweeps, metres (what the recording's moved rule sees)."""
    where = {}
    for s in json.load(open(truth))["sweeps"]:
        for o in s["objects"]:
            where.setdefault(o["id"], []).append((o["x"], o["y"]))
    return max((((p[k + 4][0] - p[k][0]) ** 2 + (p[k + 4][1] - p[k][1]) ** 2) ** 0.5 for p in where.values()
                for k in range(len(p) - 4)), default=0.0)


def _said(err):
    """The survey's first misfit as sonard said it: (sweep, what), or None."""
    m = re.search(r"survey: at sweep (\d+): (.*)", err)
    if not m:
        return None
    what = m[2]
    t = re.search(r"turned by about ([+-]\d+) gradians", what)
    if t:
        return int(m[1]), f"turned {t[1]} grad"
    for key, short in (("recorded at", "another setting"), ("not where the survey has it", "structure elsewhere"),
                       ("stands out against it", "too much stands out"), ("lines wider than any object", "new lines")):
        if key in what:
            return int(m[1]), short
    return int(m[1]), what[:40]


def section(sh, run, score, fmt, B, W, have_real, cost, score_py):
    """Runs the measurements and returns section 10's lines. run(cmd) -> (stdout, stderr, returncode)."""
    L = ["## 10. The site survey (issue 43)\n"]
    sv = {}
    for sc, _, mult, _ in SCENES:
        sh([f"{B}/sonar-sim", "--scene", sc, "--out", f"{W}/{sc}.csv", "--truth", f"{W}/{sc}.json"])
        for looks in (20, 40):
            e = f"{W}/{sc}_sv{looks}_e.csv"
            sh([f"{B}/sonar-sim", "--scene", sc, "--empty", "--seed", "5", "--sweeps", str(looks * mult), "--out", e,
                "--truth", os.devnull])
            sv[sc, looks] = f"{W}/{sc}.{looks}.survey"
            _, err, rc = run([f"{B}/sonard", "--replay", e, "--quiet", "--survey", str(looks * mult), "--survey",
                              sv[sc, looks]])
            if rc != 0:
                raise RuntimeError(f"{sc}: the survey of its empty site was refused: {err}")
        sh([f"{B}/sonar-sim", "--scene", sc, "--empty", "--seed", "6", "--sweeps", str(10 * mult), "--out",
            f"{W}/{sc}_other_e.csv", "--truth", os.devnull])
    L.append("Each pool scene replayed under the default (no survey: what stood there from the first ping is learnt "
             "about, never as the site), and with a survey of its empty site recorded first (`sonard --replay EMPTY.csv "
             "--survey N --survey FILE`, then `sonard --replay SCENE.csv --survey FILE`; the empty site is `sonar-sim "
             "--scene SCENE --empty --seed 5`, its speckle not the scene's). P / R / F1 from the second sweep "
             "(`score.py --from-sweep 1`; the default from the first in brackets), how often the watched people are "
             "found, and the objects a sweep reported on the survey's own recording and on another empty recording of "
             "the site (seed 6). 20 and 40 are the looks each angle had in the survey.\n")
    L.append("| scene | default P / R / F1 | found | survey (20) P / R / F1 | found | survey (40) P / R / F1 | found | "
             "objects a sweep, own / another empty (40) |")
    L.append("|---|---|---:|---|---:|---|---:|---:|")
    track_rows = []
    for sc, name, mult, watch in SCENES:
        cells = []
        out = f"{W}/s10-{sc}.default.jsonl"
        open(out, "w").write(sh([f"{B}/sonard", "--replay", f"{W}/{sc}.csv", "--json", "--quiet"]))
        s, s0 = score(f"{W}/{sc}.json", out, extra=["--from-sweep", "1", *watch]), score(f"{W}/{sc}.json", out)
        runs = {"default": out}

        def cell(s):
            f = s["found"]
            got, n = sum(v[0] for v in f.values()), sum(v[1] for v in f.values())
            return [f"{fmt(s['precision'])} / {fmt(s['recall'])} / **{fmt(s['F1'])}**", f"{got}/{n}" if n else "—"]
        c = cell(s)
        cells += [c[0] + f" ({fmt(s0['F1'])})", c[1]]
        for looks in (20, 40):
            out = f"{W}/s10-{sc}.{looks}.jsonl"
            open(out, "w").write(sh([f"{B}/sonard", "--replay", f"{W}/{sc}.csv", "--json", "--quiet", "--log-level", "warn",
                                     "--survey", sv[sc, looks]]))
            runs[looks] = out
            cells += cell(score(f"{W}/{sc}.json", out, extra=["--from-sweep", "1", *watch]))
        own = f"{W}/s10-{sc}.own.jsonl"
        open(own, "w").write(sh([f"{B}/sonard", "--replay", f"{W}/{sc}_sv40_e.csv", "--json", "--quiet", "--survey",
                                 sv[sc, 40]]))
        other = f"{W}/s10-{sc}.other.jsonl"
        open(other, "w").write(sh([f"{B}/sonard", "--replay", f"{W}/{sc}_other_e.csv", "--json", "--quiet", "--survey",
                                   sv[sc, 40]]))
        (n1, k1), (n2, k2) = _objects(own), _objects(other)
        cells.append(f"{n1 / max(1, k1):.2f} / {n2 / max(1, k2):.2f}")
        L.append(f"| {name} | " + " | ".join(cells) + " |")
        if sc in TRACKED:
            track_rows.append((name, [_tracks(sh, score_py, f"{W}/{sc}.json", runs[k]) for k in ("default", 20, 40)]))
    L.append("")
    lim = sh([score_py[0], os.path.join(os.path.dirname(score_py[1]), "faint_limit.py"), f"{W}/faint_sv20_e.csv",
              f"{W}/faint.csv", f"{W}/faint.json", "--window", "48"]).strip().splitlines()
    L.append("The faint targets' limit (`tools/eval/faint_limit.py EMPTY.csv faint.csv faint.json --window 48`): a "
             "detector told where each target is, its window's z against the survey's level and spread (20 looks), "
             "and the water's best window elsewhere: " + "; ".join(x.strip() for x in lim[1:]) + ".\n")
    L.append("Tracks on the moving pool scenes (`score.py --tracks`: confirmed and coasting tracks, 1 m gate): MOTA / IDF1 "
             "(ID switches).\n")
    L.append("| scene | default | survey (20) | survey (40) |")
    L.append("|---|---|---|---|")
    for name, row in track_rows:
        L.append(f"| {name} | " + " | ".join("—" if t is None else f"{t[0]:.3f} / **{t[1]:.3f}** ({t[2]})" for t in row) +
                 " |")
    L.append("")
    # A survey that no longer fits: a turned mount (the rows' angles shifted, the mount said with --angle-offset) and
    # another site of the same setting.
    L.append("A survey that no longer fits, said within a few sweeps (sonard's warning: the sweep it is said at, and "
             "what): the lanes and laps scenes with the mount turned by k gradians (the CSV's angles shifted by -k, "
             "`--angle-offset k`), and each scene with the survey of another of the same range and samples.\n")
    L.append("| survey | replayed | the sites' walls | said at sweep | what |")
    L.append("|---|---|---|---:|---|")
    for sc, turns in (("lanes", (2, 6, 12, -12, 40)), ("laps", (5, 12, -8, 30))):
        rows = [line.split(",") for line in open(f"{W}/{sc}.csv")]
        for k in turns:
            t = f"{W}/s10-turned.csv"
            with open(t, "w") as f:
                for r in rows:
                    f.write(",".join(r[:2] + [str((int(r[2]) - k) % 400)] + r[3:]))
            _, err, _ = run([f"{B}/sonard", "--replay", t, "--json", "--quiet", "--survey", sv[sc, 40], "--angle-offset",
                             str(k)])
            said = _said(err)
            L.append(f"| {sc} | turned {k:+d} grad | turned | " + (f"{said[0]} | {said[1]}" if said else "— | not said") +
                     " |")
    geometry, walls = {}, {}
    for sc, _, _, _ in SCENES:
        t = json.load(open(f"{W}/{sc}.json"))
        geometry.setdefault((t["range_m"], t["samples"]), []).append(sc)
        walls[sc] = (t.get("walls"), sc == "lanes")  # the lanes' ropes and ladder are in no other scene
    for group in geometry.values():
        for a in group:
            for b in group:
                if a != b:
                    _, err, _ = run([f"{B}/sonard", "--replay", f"{W}/{b}.csv", "--json", "--quiet", "--survey", sv[a, 40]])
                    said = _said(err)
                    same = walls[a] == walls[b]
                    L.append(f"| {a} | {b} | {'the same' if same else 'differ'} | " +
                             (f"{said[0]} | {said[1]}" if said else "— | not said") + " |")
    L.append("")
    # Refusals: each occupied scene recorded as a survey.
    L.append("Recording a survey with people in the water: each scene itself recorded as a survey (`--survey N` over "
             "its sweeps), and each empty recording (20 looks).\n")
    L.append("| recording | fastest object over 4 sweeps (truth) | kept? | why |")
    L.append("|---|---:|---|---|")
    for sc, _, mult, _ in SCENES:
        n = max(8, min(255, len(json.load(open(f"{W}/{sc}.json"))["sweeps"])))
        _, err, rc = run([f"{B}/sonard", "--replay", f"{W}/{sc}.csv", "--quiet", "--survey", str(n), "--survey",
                          f"{W}/s10-refuse.survey"])
        m = re.search(r"survey: refused, nothing written: (.*)", err)
        why = m[1] if m else ""
        why = re.sub(r" \(.*", "", why)[:110]
        L.append(f"| {sc}, occupied ({n} sweeps) | {_fastest(f'{W}/{sc}.json'):.2f} m | {'no' if rc else 'yes'} | "
                 f"{why if rc else '—'} |")
    for sc, _, mult, _ in SCENES:
        _, err, rc = run([f"{B}/sonard", "--replay", f"{W}/{sc}_sv20_e.csv", "--quiet", "--survey", str(20 * mult),
                          "--survey", f"{W}/s10-refuse.survey"])
        L.append(f"| {sc}, empty | — | {'no' if rc else 'yes'} | {'—' if not rc else err.strip().splitlines()[-1][:110]} |")
    L.append("")
    # Without a survey: the resolution floor.
    L.append("Without a survey: sizes from resolution. A detection's cells must cover one point target's footprint at "
             "its range (`--min-footprints 1`, the default: the sample's depth times the beam's 2 degrees) instead of "
             "0.05 m² at every range (`--min-area 0.05`, the old default). F1, and for the near buoys (0.2 m at 0.66, 0.9 "
             "and 1.2 m on a 5 m range, `sonar-sim --scene near`) how often each is found.\n")
    sh([f"{B}/sonar-sim", "--scene", "near", "--out", f"{W}/near.csv", "--truth", f"{W}/near.json"])
    sets = [("near buoys", f"{W}/near.csv", f"{W}/near.json", [], ["--object", "buoy_066,buoy_090,buoy_120"]),
            ("pool", f"{W}/pool.csv", f"{W}/pool.json", [], []),
            ("vehicle (world frame)", f"{W}/vehicle.csv", f"{W}/vehicle.json", ["--pose", f"{W}/vehicle.pose.csv"],
             ["--frame", "world"]),
            ("still person (the stander, from the first ping)", f"{W}/still.csv", f"{W}/still.json", [],
             ["--object", "stand"])]
    if have_real:
        sets += [("AquaScan sonar4 at 15 m", f"{W}/aq/sonar4.csv", f"{W}/aq/sonar4.truth.json", [], []),
                 ("AquaScan sonar11 at 15 m (held out)", f"{W}/aq/sonar11.csv", f"{W}/aq/sonar11.truth.json", [], [])]
    L.append("| data | --min-area 0.05 P / R / F1 | found | default (--min-footprints 1) P / R / F1 | found |")
    L.append("|---|---|---:|---|---:|")
    for name, path, truth, run_extra, score_extra in sets:
        cells = []
        for args in (["--min-area", "0.05", "--min-footprints", "0"], []):
            out = f"{W}/s10-size.jsonl"
            open(out, "w").write(sh([f"{B}/sonard", "--replay", path, "--json", "--quiet", *args, *run_extra]))
            s = score(truth, out, extra=score_extra)
            f = s["found"]
            got, n = sum(v[0] for v in f.values()), sum(v[1] for v in f.values())
            cells += [f"{fmt(s['precision'])} / {fmt(s['recall'])} / **{fmt(s['F1'])}**", f"{got}/{n}" if n else "—"]
        L.append(f"| {name} | " + " | ".join(cells) + " |")
    L.append("")
    if cost.get("beam_step_survey_us"):
        step, svs = float(cost["beam_step_us"]), float(cost["beam_step_survey_us"])
        fb, lb = (int(x) for x in cost["survey_file_bytes"].split())
        L.append(f"Cost (`make bench`, this run, 400 × 1200): the per-beam step judged against a survey {svs:.3f} µs against "
                 f"the default's {step:.3f} µs ({svs / step:.2f}×; target ≤ 1.10×: each cell a subtraction and a compare "
                 f"against a gate made once at load, and no learning); loading it {float(cost['survey_load_ms']):.1f} ms "
                 f"once; the file {fb} B against {lb} B for the levels alone ({fb / lb:.2f}×; target ≤ 2), and in RAM the "
                 f"spread block doubles the levels' 480 000 B. The co-processor takes no survey: its firmware keeps its "
                 f"own background and its bank targets (the survey's code is linked there, unused: its flash is in "
                 f"docs/coprocessor.md).\n")
    return L
