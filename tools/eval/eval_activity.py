"""eval_activity.py -- section 11 of docs/results.md (issue 46): what each person is doing (moving, standing,
struggling) on AquaScan and the simulated pools, the struggle alarm's first look, and the tracker after the fix of its
loss on real water; called by eval.py.

The thresholds (activity.h) were fixed on AquaScan sonar4 and the simulator; sonar11 is held out: run and shown, never
tuned on. The two recordings are the same minutes of probably the same five people from two viewpoints: one struggle
episode, seen twice.
"""
import json
import re

from activity import ACTS, failures, read_lines, score as activity_score

SEEDS = (1, 2, 3, 4, 5)


def _table(r, title):
    """A confusion table (labelled state down, activity across) as markdown lines."""
    cols = ACTS + ("no track",)
    L = [f"{title}\n", "| labelled | " + " | ".join(cols) + " |", "|---|" + "---:|" * len(cols)]
    for s, row in r["table"].items():
        L.append(f"| {s} | " + " | ".join(str(row[c]) for c in cols) + " |")
    return L + [""]


def _figures(r):
    first = ", ".join(f"struggler {p}: look {r['alarmed'].get(p, 'never')}" for p in r["strugglers"]) or "no struggler"
    return (f"{100 * r['cover']:.0f} % | {r['acc']:.2f} ({r['ss_ok']} of {r['ss_n']}) | {100 * r['st_bad']:.1f} % | "
            f"{100 * r['mv_ok']:.0f} % ({r['table']['moving']['moving']} of {r['mv_n']}) | {first} | "
            f"{len(r['false_alarms'])}")


def _tracks(sh, score_py, truth, out, frame):
    t = sh([score_py[0], score_py[1], truth, out, "--tracks", "--frame", frame])
    m = re.search(r"MOTA (\S+)\s+IDF1 (\S+)\s+ID switches (\d+)", t)
    return f"{float(m[2]):.3f} ({m[3]} switches)" if m else "?"


def section(sh, B, W, have_real, presets, score_py):
    """Runs the measurements and returns section 11's lines."""
    L = ["## 11. What each person is doing (issue 46)\n",
         "Each track's activity: `moving` when it travelled more than 1 m over its last two looks (half that once "
         "moving), else `standing` or `struggling` by the correlation of its raw echo in a ±0.5 m by −7..+8 gradian "
         "window with the same window a look earlier, averaged over up to three looks (struggling below 0.40); "
         "`unknown` until then (docs/activity.md). A struggle alarm is struggling in 2 of the last 3 looks. Labelled "
         "person-sweeps from the third labelled sweep, matched to confirmed or coasting tracks (least total distance, "
         "1 m gate; `tools/eval/activity.py`). The targets: ≥ 75 % covered by a known activity, standing vs struggling "
         "≥ 0.9 with ≤ 5 % of standing called struggling, moving ≥ 85 %, the struggler alarmed by its fourth look "
         "(one look to be seen, two windows, two verdicts: the soonest possible).\n",
         "| set | covered | standing vs struggling | standing called struggling | moving called moving | "
         "struggle alarm first | alarms on others |", "|---|---:|---:|---:|---:|---|---:|"]
    runs = []
    if have_real:
        for rec in ("sonar4", "sonar11"):
            for cfg in ("default", "occupied-pool"):
                out = f"{W}/act_{rec}_{cfg}.jsonl"
                open(out, "w").write(sh([f"{B}/sonard", "--replay", f"{W}/aq/{rec}.csv", "--json", "--quiet",
                                         "--log-level", "error"] + presets[cfg]))
                name = f"AquaScan {rec}" + (" (held out)" if rec == "sonar11" else " (tuning)") + f", {cfg}"
                runs.append((name, json.load(open(f"{W}/aq/{rec}.truth.json")), out, False))
    for sc, seed in [("activity", k) for k in SEEDS] + [("occupied", k) for k in SEEDS] + [("laps", k) for k in (1, 2)]:
        sh([f"{B}/sonar-sim", "--scene", sc, "--seed", str(seed), "--out", f"{W}/act_{sc}{seed}.csv", "--truth",
            f"{W}/act_{sc}{seed}.json"])
        sh([f"{B}/sonar-sim", "--scene", sc, "--empty", "--seed", str(seed + 50), "--sweeps", "20", "--out",
            f"{W}/act_e.csv", "--truth", f"{W}/act_e.json"])
        sh(["rm", "-f", f"{W}/act.sv"])
        sh([f"{B}/sonard", "--replay", f"{W}/act_e.csv", "--survey", "20", "--survey", f"{W}/act.sv", "--quiet",
            "--log-level", "error"])
        out = f"{W}/act_{sc}{seed}.jsonl"
        open(out, "w").write(sh([f"{B}/sonard", "--replay", f"{W}/act_{sc}{seed}.csv", "--survey", f"{W}/act.sv", "--json",
                                 "--quiet", "--log-level", "error"]))
        runs.append((f"simulated {sc} pool, seed {seed}, surveyed", json.load(open(f"{W}/act_{sc}{seed}.json")), out, True))
    scored = []
    for name, truth, out, sim in runs:
        r = activity_score(truth, read_lines(out))
        scored.append((name, r, sim))
        L.append(f"| {name} | {_figures(r)} |")
    L.append("")
    for name, r, sim in scored:
        bad = failures(r, sim)
        if "sonar11" not in name:
            L.append(f"- {name}: " + ("all targets met." if not bad else "missed: " + "; ".join(bad) + "."))
    L.append("")
    for name, r, sim in scored:
        if ("seed 1," in name and "laps" not in name) or not sim:
            L += _table(r, f"**{name}**: labelled state (rows) against the matched track's activity")
    for name, r, sim in scored:
        for s, v in sorted(r["corrs"].items()):
            v = sorted(v)
            if not sim or ("seed 1," in name and "laps" not in name):
                L.append(f"- {name}, still ones labelled {s}: echo correlation {v[0]:.2f} .. {v[-1]:.2f} "
                         f"(median {v[len(v) // 2]:.2f}, {len(v)} person-sweeps)")
    L.append("")
    if have_real:
        L.append("**The tracker on real water (item 5).** The occupied-pool preset, IDF1 and ID switches "
                 "(`score.py --tracks`):\n")
        L += ["| recording | sonard (interacting models, deferral) | near constant velocity alone |", "|---|---|---|"]
        for rec in ("sonar4", "sonar11"):
            row = []
            for extra in ([], ["--track-models", "cv"]):
                out = f"{W}/trk_{rec}_{len(extra)}.jsonl"
                open(out, "w").write(sh([f"{B}/sonard", "--replay", f"{W}/aq/{rec}.csv", "--json", "--quiet",
                                         "--log-level", "error"] + presets["occupied-pool"] + extra))
                row.append(_tracks(sh, score_py, f"{W}/aq/{rec}.truth.json", out, "body"))
            L.append(f"| AquaScan {rec}" + (" (held out)" if rec == "sonar11" else "") + f" | {row[0]} | {row[1]} |")
        L.append("")
    return L
