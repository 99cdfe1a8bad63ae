#!/bin/sh
# e2e.sh -- end to end: simulated scenes through sonard --replay, scored against the truth; bad input and options.
# Usage: sh tests/e2e.sh BUILD_DIR. Ends with "N passed, N failed"; exits 1 if anything failed.
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-e2e.XXXXXX)
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"

# Scenes. Pool: walls throughout, two gate posts from sweep 2, a moving buoy from sweep 3; scored
# with sonard's DEFAULT configuration (median 5, auto background, CFAR). Open water: objects from
# the first ping, no walls; scored with the default and with --background range. Targets:
# precision and recall >= 0.95, centroid error <= 0.3 m.
"$B/sonar-sim" --scene pool --out "$T/pool.csv" --truth "$T/pool.json"
"$B/sonar-sim" --scene open --seed 7 --out "$T/open.csv" --truth "$T/open.json"
"$B/sonard" --replay "$T/pool.csv" --json > "$T/pool.jsonl" 2> "$T/pool.err"
check "sonar-sim: each wall's return starts at the nearest wall inside the 2-degree beam (causal, as an echo is)" \
    python3 tests/scene_check.py "$T/pool.csv" "$T/pool.json"
check "pool scene, default config: precision/recall >= 0.95, error <= 0.3 m" \
    python3 tools/eval/score.py "$T/pool.json" "$T/pool.jsonl" --min-precision 0.95 --min-recall 0.95 --max-error 0.3
"$B/sonard" --replay "$T/open.csv" --json > "$T/opendef.jsonl" 2>/dev/null
check "open water, default config: precision/recall >= 0.95, error <= 0.3 m" \
    python3 tools/eval/score.py "$T/open.json" "$T/opendef.jsonl" --min-precision 0.95 --min-recall 0.95 --max-error 0.3
"$B/sonard" --replay "$T/open.csv" --json --background range > "$T/open.jsonl" 2>/dev/null
check "open water, --background range: precision/recall >= 0.95, error <= 0.3 m" \
    python3 tools/eval/score.py "$T/open.json" "$T/open.jsonl" --min-precision 0.95 --min-recall 0.95 --max-error 0.3
"$B/sonard" --replay "$T/pool.csv" --json --median 5x5 > "$T/pool55.jsonl" 2>/dev/null
check "pool scene, --median 5x5 (the study's 2-D filter): recall >= 0.95" \
    python3 tools/eval/score.py "$T/pool.json" "$T/pool55.jsonl" --min-recall 0.95 --max-error 0.3
# The study's method (range background, plain subtraction) on the pool: it finds the walls.
"$B/sonard" --replay "$T/pool.csv" --json --background range --bg-margin 0 > "$T/study.jsonl" 2>/dev/null
python3 tools/eval/score.py "$T/pool.json" "$T/study.jsonl" --label "  study's method on the pool: " | head -1
fa=$(python3 tools/eval/score.py "$T/pool.json" "$T/study.jsonl" | sed -n 's/.*false alarms\/sweep \([0-9.]*\).*/\1/p' | tail -1)
check "the study's range background keeps the walls: >= 1 false alarm a sweep (got $fa)" \
    awk -v f="$fa" 'BEGIN { exit !(f >= 1.0) }' 

# Real water without a preset (issue 23): the scenes with the AquaScan pool's speckle (K-distributed
# water, a 10-degree echo spread), people in the water from the first ping, a faint far swimmer, one
# who floats still for 3 minutes; sonard's default configuration. The floors are regression guards
# under today's figures (0.917, 0.858, 0.859; the issue's 0.95 is not met: docs/results.md); the
# empty pool's false alarms and the still person are the issue's own targets.
for sc in occupied far still; do
    "$B/sonar-sim" --scene $sc --out "$T/$sc.csv" --truth "$T/$sc.json"
    "$B/sonard" --replay "$T/$sc.csv" --json --quiet > "$T/$sc.jsonl" 2>/dev/null
done
check "occupied pool (people from the first ping), default config: F1 >= 0.88" \
    python3 tools/eval/score.py "$T/occupied.json" "$T/occupied.jsonl" --min-f1 0.88 --label "  occupied: "
check "far swimmers scene (four at 8.5-12.5 m, echoes 95-105), default config: F1 >= 0.82, each found in >= 70 % of sweeps" \
    python3 tools/eval/score.py "$T/far.json" "$T/far.jsonl" --min-f1 0.82 --object far_a,far_b,far_c,far_d --min-found 0.7 --label "  far: "
check "still scene, default config: F1 >= 0.82; the person floating still found in >= 95 % of the still sweeps" \
    python3 tools/eval/score.py "$T/still.json" "$T/still.jsonl" --min-f1 0.82 --object floater --still --min-found 0.95 --label "  still: "
check "still scene: the floater's track says how long it has stood still (still_s within 15 % of the truth)" python3 - "$T/still.json" "$T/still.jsonl" <<'PY'
import json, math, sys
truth = json.load(open(sys.argv[1]))["sweeps"]
lines = [json.loads(l) for l in open(sys.argv[2])]
still = [s for s in truth for o in s["objects"] if o["id"] == "floater" and o["vx"] == 0 and o["vy"] == 0]
f = [o for o in truth[-1]["objects"] if o["id"] == "floater"][0]
want = (f["t_us"] - [o for o in still[0]["objects"] if o["id"] == "floater"][0]["t_us"]) * 1e-6
near = [t for t in lines[-1]["tracks"] if math.hypot(t["x_m"] - f["x"], t["y_m"] - f["y"]) < 1.0]
assert near, "no track on the floater at the end"
got = near[0]["still_s"]
print(f"  still for {want:.0f} s by the truth, still_s {got:.1f}")
assert abs(got - want) <= 0.15 * want, (got, want)
PY
# Hybrid scenes (sonar-sim --water, issue 51): a scene's people drawn into a recording of water. On the simulated
# empty pool it must change nothing but the people's cells, cut the sweeps as sonard does, and find them as the
# simulated scene does (F1 0.923 on the occupied scene; the hybrid over its empty water: 0.940).
"$B/sonar-sim" --scene occupied --empty --seed 3 --out "$T/water.csv" --truth "$T/x.json"
"$B/sonar-sim" --scene occupied --water "$T/water.csv" --out "$T/hyb.csv" --truth "$T/hyb.json"
"$B/sonard" --replay "$T/hyb.csv" --json --quiet > "$T/hyb.jsonl" 2>/dev/null
check "sonar-sim --water: the people drawn on the water and nothing else changed; sonard's sweeps are the truth's" \
    python3 tests/water_check.py "$T/water.csv" "$T/hyb.csv" "$T/hyb.json" --sweeps-from "$T/hyb.jsonl"
check "the occupied scene on recorded empty water, default config: F1 >= 0.88, as on the simulator's" \
    python3 tools/eval/score.py "$T/hyb.json" "$T/hyb.jsonl" --min-f1 0.88 --label "  hybrid: "
"$B/sonar-sim" --scene pool --water "$T/water.csv" --out "$T/hx.csv" --truth "$T/hx.json" 2> "$T/hx.err"; rc=$?
check "sonar-sim --water with a scene of the older echo model: exit 2, named, nothing written" \
    sh -c "test $rc -eq 2 && grep -q \"scene 'pool' is not one with the AquaScan pool's statistics\" '$T/hx.err' && test ! -e '$T/hx.csv'"
printf 'Angle (gradian);Intensity (0-255)\n100;1;2;3\n' > "$T/untimed.csv"
"$B/sonar-sim" --scene occupied --water "$T/untimed.csv" --out "$T/hx.csv" --truth "$T/hx.json" 2> "$T/hx.err"; rc=$?
check "sonar-sim --water over rows without times: exit 2, the file and line named" \
    sh -c "test $rc -eq 2 && grep -q 'untimed.csv:2: the rows have no times' '$T/hx.err'"
{ head -5 "$T/water.csv"; echo "garbage,row"; sed -n '6,$p' "$T/water.csv"; } > "$T/gwater.csv"
"$B/sonar-sim" --scene occupied --water "$T/gwater.csv" --out "$T/hg.csv" --truth "$T/hg.json" 2> "$T/hg.err"; rc=$?
check "sonar-sim --water, a malformed row: said by line and skipped, every other row drawn" \
    sh -c "test $rc -eq 0 && grep -q 'gwater.csv:6: .*(row skipped)' '$T/hg.err' && test \$(wc -l < '$T/hg.csv') -eq \$(wc -l < '$T/water.csv')"

# The water's transients (sonar-sim --transients; calibrated against emptied sonar4 in make realdata): short-lived
# echoes all over the empty pool, several a sweep where the plain water gives about one; the older scenes refuse it.
"$B/sonar-sim" --scene occupied --empty --transients --seed 3 --out "$T/wt.csv" --truth "$T/x.json"
"$B/sonard" --replay "$T/wt.csv" --json --quiet > "$T/wt.jsonl" 2>/dev/null
"$B/sonard" --replay "$T/water.csv" --json --quiet > "$T/water.jsonl" 2>/dev/null
check "sonar-sim --transients: the empty pool's false objects a sweep at least three times the plain water's, few lasting" \
    python3 - "$T/wt.jsonl" "$T/water.jsonl" <<'PY'
import json, subprocess, sys
m = [json.loads(subprocess.run([sys.executable, "tools/eval/transients.py", j, "--json"], capture_output=True, text=True,
                               check=True).stdout) for j in sys.argv[1:]]
print(f"  with transients {m[0]['detections_a_sweep']:.2f} a sweep, plain water {m[1]['detections_a_sweep']:.2f}; "
      f"persistent places {m[0]['persistent_places']}")
assert m[0]["detections_a_sweep"] >= 3 * max(m[1]["detections_a_sweep"], 0.5) and m[0]["persistent_places"] == 0, m
PY
"$B/sonar-sim" --scene pool --transients --out "$T/hx.csv" --truth "$T/hx.json" 2> "$T/hx.err"; rc=$?
check "sonar-sim --transients with a scene of the older echo model: exit 2, named" \
    sh -c "test $rc -eq 2 && grep -q 'transients needs a scene with the AquaScan pool' '$T/hx.err'"

fa=$(python3 tools/eval/score.py "$T/pool.json" "$T/pool.jsonl" | sed -n 's/.*false alarms\/sweep \([0-9.]*\).*/\1/p')
check "pool scene, default config: <= 0.1 false alarms a sweep (got $fa)" awk -v f="$fa" 'BEGIN { exit !(f <= 0.1) }'

# Tracking (issue 10): the moving scenes, scored against the truth IDs. The floors below are what
# the tracker does today with margin (regression guards; the issue's targets of 0.95 are not met
# yet, see docs/results.md section 5). Each line also prints the full tracking table.
for sc in sector moving; do
    "$B/sonar-sim" --scene $sc --out "$T/$sc.csv" --truth "$T/$sc.json"
    "$B/sonard" --replay "$T/$sc.csv" --json --quiet --min-points 8 > "$T/$sc.jsonl" 2>/dev/null
    python3 tools/eval/score.py "$T/$sc.json" "$T/$sc.jsonl" --tracks --label "  $sc: " | tail -1
done
check "tracking, sector scene (back and forth, 26 passes): IDF1 >= 0.90, MOTA >= 0.80, no ID switch" \
    python3 tools/eval/score.py "$T/sector.json" "$T/sector.jsonl" --tracks --min-idf1 0.90 --min-mota 0.80 --max-idsw-per-100 0
check "tracking, moving scene (24 turns: crossing, turning, fading, 1.5 m/s): IDF1 >= 0.70, MOTA >= 0.65, velocity error <= 0.26 m/s" \
    python3 tools/eval/score.py "$T/moving.json" "$T/moving.jsonl" --tracks --min-idf1 0.70 --min-mota 0.65 --max-vel-error 0.26
# Deferred association (issue 37): the next look may revise the IDs just published, each revision
# said; --track-late gives every sweep one sweep late, relabelled, with none.
"$B/sonard" --replay "$T/moving.csv" --json --quiet --min-points 8 --track-late on > "$T/moving_late.jsonl" 2>/dev/null
check "deferred association: the moving scene's revisions are said, and --track-late gives each sweep once, relabelled by them, with none" \
    python3 - "$T/moving.jsonl" "$T/moving_late.jsonl" <<'PY'
import json, sys
sys.path.insert(0, "tools/eval")
import score
live = {d["sweep"]: d for d in map(json.loads, open(sys.argv[1]))}
late = [json.loads(l) for l in open(sys.argv[2])]
assert sum(1 for d in live.values() if d.get("revisions")) >= 1, "no revision on the moving scene"
assert [d["sweep"] for d in late] == sorted(live), "not every sweep once, in order"
want = score.late(live)
for d in late:
    assert "revisions" not in d, d["sweep"]
    got = [(t["id"], t["x_m"]) for t in d["tracks"]]
    assert got == [(t["id"], t["x_m"]) for t in want[d["sweep"]]["tracks"]], (d["sweep"], got)
PY
check "tracking, moving scene one sweep late (--track-late): IDF1 >= 0.72" \
    python3 tools/eval/score.py "$T/moving.json" "$T/moving_late.jsonl" --tracks --min-idf1 0.72
# Published on the first hit, a track has no velocity yet: it is assigned after those that have one
# (IDF1 0.956 and MOTA 0.909 today; assigned with them, 0.737 / 0.855 and two ID switches).
"$B/sonard" --replay "$T/sector.csv" --json --quiet --min-points 8 --track-confirm 1 > "$T/sector1.jsonl" 2>/dev/null
check "tracking, sector scene, --track-confirm 1: IDF1 >= 0.93, MOTA >= 0.88, no ID switch" \
    python3 tools/eval/score.py "$T/sector.json" "$T/sector1.jsonl" --tracks --min-idf1 0.93 --min-mota 0.88 --max-idsw-per-100 0
# The tracks the autopilot is sent (OBSTACLE_DISTANCE_3D: those hit in the sweep): 0.982 / 0.991 today.
check "tracking, sector scene, --track-confirm 1, the tracks sent to the autopilot: IDF1 >= 0.95, MOTA >= 0.95" \
    python3 tools/eval/score.py "$T/sector.json" "$T/sector1.jsonl" --tracks --states confirmed --min-idf1 0.95 --min-mota 0.95
check "tracks: IDs never reused, each line's tracks carry id/state/x_m/y_m/vx_mps/vy_mps/age/hits/mode/kind" python3 -c "
import json, sys
seen_ids, last = set(), {}
for line in open('$T/moving.jsonl'):
    d = json.loads(line)
    ids = [t['id'] for t in d['tracks']]
    assert len(ids) == len(set(ids)), ids
    revised = {r['id'] for r in d.get('revisions', [])} | {r['now'] for r in d.get('revisions', [])}
    for t in d['tracks']:
        assert {'id', 'state', 'x_m', 'y_m', 'vx_mps', 'vy_mps', 'age', 'hits', 'mode', 'kind'} <= set(t), t
        assert t['state'] in ('tentative', 'confirmed', 'coasting'), t
        assert t['mode'] in ('moving', 'turning', 'resting'), t
        assert t['kind'] in ('new', 'moving', 'resting', 'still'), t
        # an id once gone never comes back, unless a revision said the last sweep's was it
        assert t['id'] not in seen_ids or t['id'] in last or t['id'] in revised, t['id']
    seen_ids |= set(ids)
    last = set(ids)
    assert all(det['utime'] > 0 for det in d['detections'])
"
"$B/sonard" --replay "$T/sector.csv" --json --quiet --track off > "$T/off.jsonl" 2>/dev/null
check "--track off: detections still, no tracks in the JSON" sh -c "grep -q '\"detections\":\\[{' '$T/off.jsonl' && ! grep -q '\"tracks\"' '$T/off.jsonl'"
"$B/sonard" --replay "$T/sector.csv" --track-confirm 4 --track-window 3 > "$T/conf.out" 2>&1; rc=$?
check "--track-confirm 4 --track-window 3 is refused (exit 2), naming both" \
    sh -c "test $rc -eq 2 && grep -q -- '--track-confirm 4 exceeds --track-window 3' '$T/conf.out'"

# A moving vehicle (issue 11): the 30 x 16 m pool seen while the vehicle goes up and down it at
# 0.5 m/s and its heading swings at 30 degrees/s. With the pose (--pose) the background is kept in
# the world and the tracks too; the body-frame baseline (no pose) is printed beside it.
# Progress: a line on stderr when it is a terminal (a pty here), none in a log.
check "--replay on a terminal: a progress line (beams, sweeps, rate, percent); none when stderr is a file" python3 - "$B/sonard" "$T/pool.csv" "$T/pool.err" <<'PY'
import os, pty, re, subprocess, sys
m, s = pty.openpty()
p = subprocess.Popen([sys.argv[1], "--replay", sys.argv[2], "--json", "--no-lcm"], stdout=subprocess.DEVNULL, stderr=s)
os.close(s)
out = b""
while True:
    try:
        d = os.read(m, 4096)
    except OSError:
        break
    if not d:
        break
    out += d
assert p.wait() == 0
text = out.decode()
last = [x for x in re.split(r"[\r\n]+", text) if "beams/s" in x]
assert last, text
got = re.search(r"beams (\d+)  sweeps (\d+)  \d+ beams/s  100 %", last[-1])
assert got, last[-1]
used = re.search(r"(\d+) rows used, \d+ skipped, (\d+) sweeps", text)
assert got.group(1) == used.group(1) and got.group(2) == used.group(2), (last[-1], used.group(0))
log = open(sys.argv[3]).read()
assert "beams/s" not in log and "\r" not in log, log
print(last[-1].strip())
PY
"$B/sonar-sim" --scene vehicle --out "$T/veh.csv" --truth "$T/veh.json" --pose-out "$T/veh.pose.csv"
"$B/sonard" --replay "$T/veh.csv" --pose "$T/veh.pose.csv" --json --min-points 8 --csv-out "$T/veh.rec.csv" \
    --stage raw > "$T/veh.jsonl" 2> "$T/veh.err"
"$B/sonard" --replay "$T/veh.csv" --json --quiet --min-points 8 > "$T/vehb.jsonl" 2>/dev/null
python3 tools/eval/score.py "$T/veh.json" "$T/vehb.jsonl" --label "  vehicle, body frame (no pose): " | tail -1
python3 tools/eval/score.py "$T/veh.json" "$T/veh.jsonl" --frame world --tracks --label "  vehicle, world frame: " | tail -2
check "vehicle scene with --pose: world-frame detection F1 >= 0.90" \
    python3 tools/eval/score.py "$T/veh.json" "$T/veh.jsonl" --frame world --min-f1 0.90
check "vehicle scene: the posts and the buoy are tracked standing still (<= 0.05 m/s) while the vehicle moves" \
    python3 tools/eval/score.py "$T/veh.json" "$T/veh.jsonl" --frame world --tracks --max-static-speed 0.05
check "vehicle scene: the pose is said to be known, and every sweep is tracked in the world frame" sh -c "
    grep -q 'pose: known at 1728153122.000 s: detections and tracks in the world frame' '$T/veh.err' &&
    test \$(grep -c '\"frame\":\"world\"' '$T/veh.jsonl') -eq 18"
"$B/sonard" --replay "$T/veh.rec.csv" --json --quiet --min-points 8 > "$T/veh2.jsonl" 2>/dev/null
# The recording rounds each pose to 1 mm and 0.001 degrees: a cell on the threshold can go either way and
# move a centroid by a few cm (2.3 cm once on this scene), so 5 cm.
check "the recording carries each beam's pose: replayed without --pose, the same detections (5 cm) and track IDs" python3 -c "
import json
a = [json.loads(l) for l in open('$T/veh.jsonl')]
b = [json.loads(l) for l in open('$T/veh2.jsonl')]
assert len(a) == len(b) == 18, (len(a), len(b))
for x, y in zip(a, b):
    assert [t['id'] for t in x['tracks']] == [t['id'] for t in y['tracks']], x['sweep']
    assert len(x['detections']) == len(y['detections']), x['sweep']
    for p, q in zip(x['detections'], y['detections']):
        assert abs(p['north_m'] - q['north_m']) < 0.05 and abs(p['east_m'] - q['east_m']) < 0.05, (x['sweep'], p, q)
"
# A robot in a tank (issue 54): walls in one look, their echoes, interference streaks (docs/results.md section 14).
"$B/sonar-sim" --scene tank --out "$T/tank.csv" --truth "$T/tank.json" --pose-out "$T/tank.pose.csv"
"$B/sonard" --replay "$T/tank.csv" --json > "$T/tank.jsonl" 2> "$T/tank.err"
python3 tools/eval/score.py "$T/tank.json" "$T/tank.jsonl" --label "  tank, objects from the first look: " | tail -1
check "tank scene: every streak the truth drew is left out as interference, and no other beam (said once)" python3 -c "
import json, re
t = json.load(open('$T/tank.json'))
drawn = sum(len(s['streaks']) for s in t['sweeps'])
err = open('$T/tank.err').read()
m = re.search(r'(\\d+) beams left out as interference', err)
assert drawn > 0 and m and int(m.group(1)) == drawn, (drawn, m and m.group(0))
assert err.count('stands out along most of its length') == 1, err
"
check "tank scene: walls are structure and their echoes 'wall echo' in one look; every prop found, objects F1 >= 0.95 from the first look (the target)" sh -c "
    grep -q '\"kind\":\"wall echo\"' '$T/tank.jsonl' && test \$(grep -o '\"kind\":\"structure\"' '$T/tank.jsonl' | wc -l) -ge 40 &&
    python3 tools/eval/score.py '$T/tank.json' '$T/tank.jsonl' --min-recall 1.0 --min-f1 0.95"
"$B/sonar-sim" --scene near --out "$T/near.csv" --truth "$T/near.json"
"$B/sonard" --replay "$T/near.csv" --json --quiet > "$T/near.jsonl" 2>/dev/null
check "near scene: the 0.2 m buoys at 0.66-1.2 m are objects in every sweep (no wall, no echo, no streak)" \
    python3 tools/eval/score.py "$T/near.json" "$T/near.jsonl" --min-recall 1.0 --min-precision 1.0
python3 - "$T/blank.csv" <<'PY'
import random, sys
random.seed(3)
rows = []
for i in range(240):
    s = ["0"] * 300 if i in (50, 51) else ["255"] * 300 if i == 52 else [str(random.randint(1, 30)) for _ in range(300)]
    rows.append(f'{1700000000 + i // 10},{(i % 10) * 100000000},{(i * 5) % 400},"{" ".join(s)}"')
open(sys.argv[1], "w").write("\n".join(rows) + "\n")
PY
"$B/sonard" --replay "$T/blank.csv" --range 10 > "$T/blank.out" 2>&1
check "blank beams (every sample 0, or 255): each named by its angle and time, skipped, counted" sh -c "
    grep -q 'beam at 250 gradians (1700000005.000 s): all 300 samples 0: skipped (nothing heard)' '$T/blank.out' &&
    grep -q 'beam at 260 gradians (1700000005.200 s): all 300 samples 255: skipped (saturated)' '$T/blank.out' &&
    grep -q '3 blank beams skipped, 0 beams left out as interference' '$T/blank.out' &&
    grep -q '240 rows used' '$T/blank.out'"
# The obstacle map on the same run against the scene's walls and objects (tools/eval/wallfit.c; the
# figures are in docs/results.md section 6): regression guards below today's 0.021 m and 92.5 %.
"$B/sonar-wallfit" --replay "$T/veh.csv" --pose "$T/veh.pose.csv" --scene vehicle > "$T/wallfit.out" 2>/dev/null
check "vehicle scene: the obstacle map's world echo points lie within one range cell (0.025 m) RMS of the walls" \
    awk '/world echo points .* of a wall: / { ok = $NF == "m" && $(NF-1) + 0 <= 0.025 && $(NF-1) + 0 > 0 } END { exit !ok }' \
    "$T/wallfit.out"
check "vehicle scene: >= 90 % of OBSTACLE_DISTANCE sectors within 0.1 m, <= 4 % farther than the obstacle (the unsafe side)" \
    python3 -c "
import re, sys
t = open('$T/wallfit.out').read()
w = re.search(r'map with the poses \(world memory\): (\d+) sectors .*?, ([\d.]+) % within 0.1 m', t)
f = re.search(r'beyond 0.1 m: \d+ nearer than the obstacle \(the safe side\), \d+ farther \(([\d.]+) % of the sectors\)', t)
print('  world memory: %s sectors, %s %% within 0.1 m, %s %% farther' % (w.group(1), w.group(2), f.group(1)))
sys.exit(not (int(w.group(1)) > 3000 and float(w.group(2)) >= 90.0 and float(f.group(1)) <= 4.0))"
head -301 "$T/veh.pose.csv" > "$T/short.pose.csv" # 30 s of a 113 s run
"$B/sonard" --replay "$T/veh.csv" --pose "$T/short.pose.csv" --json --min-points 8 > "$T/short.jsonl" 2> "$T/short.err"
check "a pose that stops: said once, body-frame processing from then on, the tracks keep their IDs" sh -c "
    grep -q 'pose: stale (none within 1 s of the beam at 1728153152' '$T/short.err' &&
    grep -q '\"frame\":\"world\"' '$T/short.jsonl' && tail -1 '$T/short.jsonl' | grep -q '\"frame\":\"body\"' &&
    python3 -c \"
import json
ids = [t['id'] for l in open('$T/short.jsonl') for t in json.loads(l)['tracks']]
assert max(ids) < 40, max(ids)\""
printf 'utime_us,north_m,east_m,yaw_deg\n1728153122000000,0,0,0\n1728153122100000,0,0,x\n1728153122000000,0,0,0\n1728153122200000,500,0,0\n' > "$T/bad.pose.csv"
"$B/sonard" --replay "$T/veh.csv" --pose "$T/bad.pose.csv" --json --quiet --sweeps 1 > /dev/null 2> "$T/bad.err"; rc=$?
check "bad pose rows: each named by line and skipped, the replay goes on" sh -c "test $rc -eq 0 &&
    grep -q 'bad.pose.csv:3: yaw_deg .x. is not a number; row skipped' '$T/bad.err' &&
    grep -q 'bad.pose.csv:4: pose at 1728153122.000000 s is not later than the pose before it; row skipped' '$T/bad.err' &&
    grep -q 'bad.pose.csv:5: pose at 1728153122.200000 s is a jump' '$T/bad.err' &&
    grep -q -- '--pose .*bad.pose.csv: 3 rows skipped' '$T/bad.err'"
printf 'time,north,east,yaw\n' > "$T/hdr.pose.csv"
"$B/sonard" --replay "$T/veh.csv" --pose "$T/hdr.pose.csv" > /dev/null 2> "$T/hdr.err"; rc=$?
check "a pose file without the header: exit 2, named" sh -c "test $rc -eq 2 && grep -q 'hdr.pose.csv:1: the header has no column utime_us' '$T/hdr.err'"

# The shipped preset parses and runs (scored on the real recordings by tests/realdata.sh).
check "docs/presets/occupied-pool.conf is read and runs" sh -c "'$B/sonard' --replay '$T/open.csv' --json --quiet --config docs/presets/occupied-pool.conf > '$T/preset.jsonl' && test -s '$T/preset.jsonl'"

# Several --config files apply in order; a string from the first survives reading the second; flags win.
printf 'csv-out = %s\nstage = raw\nmin-points = 7\n' "$T/multi.csv" > "$T/a.conf"
printf '# the second file\nmin-points = 60000\nmedian = 3\n' > "$T/b.conf"
"$B/sonard" --replay "$T/pool.csv" --json --quiet --config "$T/a.conf" --config "$T/b.conf" > "$T/multi.jsonl" 2>&1
check "two --config files: the later overrides (no detections at 60000 points), the earlier's csv-out kept" \
    sh -c "test \$(wc -l < '$T/multi.csv') -eq \$(wc -l < '$T/pool.csv') && ! grep -q '\"detections\":\\[{' '$T/multi.jsonl'"
"$B/sonard" --replay "$T/pool.csv" --json --quiet --config "$T/a.conf" --config "$T/b.conf" --min-points 20 > "$T/multi2.jsonl" 2>&1
check "a flag overrides both --config files" grep -q x_m "$T/multi2.jsonl"

# Exports: every row comes out, and the export replays.
"$B/sonard" --replay "$T/pool.csv" --quiet --csv-out "$T/fg.csv" --stage foreground > /dev/null 2>&1
check "--csv-out writes one row per beam" test "$(wc -l < "$T/fg.csv")" -eq "$(wc -l < "$T/pool.csv")"
check "--csv-out foreground replays cleanly (exit 0, no warning said)" sh -c "'$B/sonard' --replay '$T/fg.csv' --quiet --log-level warn --background off > '$T/fgr.out' 2>&1 && ! test -s '$T/fgr.out'"

# Bad rows: named with file and line, skipped; the run goes on; exit 0 while something was usable.
head -3 "$T/pool.csv" > "$T/bad.csv"
printf '1,0,12,"1 2 abc"\nnot,a,row\n1,0,13,"300 1 2"\n' >> "$T/bad.csv"
sed -n 4,6p "$T/pool.csv" >> "$T/bad.csv"
"$B/sonard" --replay "$T/bad.csv" --quiet > /dev/null 2> "$T/bad.err"; rc=$?
check "bad rows: exit 0 with usable rows" test "$rc" -eq 0
check "bad rows: file and line named" grep -q "bad.csv:4: sample 3 'abc' is not a number; row skipped" "$T/bad.err"
check "bad rows: over 255 named" grep -q "bad.csv:6: sample 1 is 300, outside 0..255" "$T/bad.err"
check "bad rows: summary counts" grep -qE "3 (rows )?skipped" "$T/bad.err"
"$B/sonard" --replay "$T/bad.csv" --quiet --log-level warn > /dev/null 2> "$T/badw.err"
check "bad rows at --log-level warn: named, counted, and nothing else said" \
    sh -c "grep -q 'bad.csv:4:' '$T/badw.err' && grep -q '3 rows skipped' '$T/badw.err' && ! grep -q 'rows used' '$T/badw.err'"
printf 'garbage\n\001\002\003\nx,y,z\n' > "$T/allbad.csv"
"$B/sonard" --replay "$T/allbad.csv" > /dev/null 2>&1; rc=$?
check "nothing usable: exit 1" test "$rc" -eq 1
head -c 300000 /dev/urandom > "$T/random.csv"
"$B/sonard" --replay "$T/random.csv" > /dev/null 2>&1; rc=$?
check "random bytes: no crash, exit 1" test "$rc" -eq 1

# Recordings as people keep them: gzip-compressed, read whole or cut short (the rows before the cut
# used, the cut named); piped in compressed, named once rather than a garbage row per line.
gzip -c "$T/pool.csv" > "$T/pool.csv.gz"
"$B/sonard" --replay "$T/pool.csv" --json --quiet --no-lcm > "$T/plain.jsonl" 2>/dev/null
"$B/sonard" --replay "$T/pool.csv.gz" --json --quiet --no-lcm > "$T/gz.jsonl" 2> "$T/gz.err"; rc=$?
check "a gzip-compressed recording replays to the same detections as the plain one" sh -c "test $rc -eq 0 && cmp -s '$T/plain.jsonl' '$T/gz.jsonl'"
head -c $(( $(wc -c < "$T/pool.csv.gz") / 2 )) "$T/pool.csv.gz" > "$T/cut.csv.gz"
"$B/sonard" --replay "$T/cut.csv.gz" --json --quiet --no-lcm > "$T/cut.jsonl" 2> "$T/cut.err"; rc=$?
check "a gzip recording cut short: its rows used (exit 0), the cut named with file and line" sh -c "test $rc -eq 0 &&
    test -s '$T/cut.jsonl' && grep -q 'cut.csv.gz:[0-9]*: compressed (gzip) and truncated or corrupt' '$T/cut.err'"
"$B/sonard" --replay - --quiet --no-lcm < "$T/pool.csv.gz" > /dev/null 2> "$T/gzin.err"; rc=$?
check "gzip data on stdin: exit 1, named once" sh -c "test $rc -eq 1 && test \$(grep -c 'gzip-compressed data, not CSV rows' '$T/gzin.err') -eq 1"

# The range changed mid-run (an operator's --range on a live sonar, or two recordings joined): said
# once with the beam's time, the sweep cut there, the background relearnt, nothing else lost.
n=$(wc -l < "$T/pool.csv")
head -$((n / 2)) "$T/pool.csv" > "$T/rchg.csv"
tail -n +$((n / 2 + 1)) "$T/pool.csv" | sed 's/range_m=[0-9.]*/range_m=15.0000/' >> "$T/rchg.csv"
"$B/sonard" --replay "$T/rchg.csv" --json --no-lcm > "$T/rchg.jsonl" 2> "$T/rchg.err"; rc=$?
check "a range change mid-run: said once, the sweep cut, every beam still used (exit 0)" sh -c "test $rc -eq 0 &&
    test \$(grep -c 'range: 1200 samples over 15.00 m from the beam at .* (was 1200 over 12.00 m)' '$T/rchg.err') -eq 1 &&
    test \$(grep -o '\"beams\":[0-9]*' '$T/rchg.jsonl' | awk -F: '{s += \$2} END {print s}') -eq $n"

# Values that once overflowed (issue 8): a timestamp near 9.2e18 s, range metadata 1e308, a cast-overflowing sample period.
head -3 "$T/pool.csv" > "$T/ovf.csv"
sed -n 4p "$T/pool.csv" | sed 's/^[0-9]*,/9223372036854775807,/' >> "$T/ovf.csv"
sed -n 5p "$T/pool.csv" | sed 's/$/,range_m=1e308/' >> "$T/ovf.csv"
sed -n 6p "$T/pool.csv" | sed 's/$/,sample_period=1e30/' >> "$T/ovf.csv"
"$B/sonard" --replay "$T/ovf.csv" --quiet > /dev/null 2> "$T/ovf.err"; rc=$?
check "timestamp 9.2e18 s: named and skipped" grep -q "ovf.csv:4: timestamp seconds '9223372036854775807' is not an integer within" "$T/ovf.err"
check "range_m=1e308: named and skipped" grep -q "ovf.csv:5: metadata range_m=1e308 is not a number in 0..1000; row skipped" "$T/ovf.err"
check "sample_period=1e30: named and skipped, the good rows used (exit 0)" sh -c "grep -q 'ovf.csv:6: metadata sample_period=1e30' '$T/ovf.err' && test $rc -eq 0"
"$B/sonard" --replay "$T/pool.csv" --config "$T" > /dev/null 2> "$T/err"; rc=$?
check "--config given a directory: exit 2, named" sh -c "test $rc -eq 2 && grep -q -- '--config $T: not a regular file' '$T/err'"

# A key valid alone but not with a replay, in a file: refused at its FILE:LINE, after the file's unknown keys are said.
printf 'rnage = 12\npose-lcm = memq://\n' > "$T/vehicle.conf"
"$B/sonard" --replay "$T/pool.csv" --config "$T/vehicle.conf" > /dev/null 2> "$T/err"; rc=$?
check "pose-lcm in a file used with --replay: exit 2 at vehicle.conf:2, the unknown key 'rnage' said before it" sh -c "
test $rc -eq 2 && sed -n 1p '$T/err' | grep -q \"vehicle.conf:1: unknown key 'rnage'\" &&
sed -n 2p '$T/err' | grep -q 'vehicle.conf:2: --pose-lcm URL is for a live sonar' || { cat '$T/err'; exit 1; }"

# Configuration errors name the option, the value and the unit.
"$B/sonard" --replay "$T/pool.csv" --range 0 2> "$T/err" > /dev/null; rc=$?
check "--range 0 rejected with exit 2" test "$rc" -eq 2
check "--range error names unit" grep -q -- "--range: '0' is not a number in 1..60 metres" "$T/err"
"$B/sonard" --replay "$T/pool.csv" --median 4 2> "$T/err" > /dev/null
check "--median 4 rejected" grep -q -- "--median: '4' is even" "$T/err"
"$B/sonard" --replay "$T/pool.csv" --background median 2> "$T/err" > /dev/null
check "--background typo rejected" grep -q -- "--background: 'median' is not auto, per-angle, range or off" "$T/err"
"$B/sonard" --replay "$T/pool.csv" --clusters 2> "$T/err" > /dev/null
check "missing value rejected" grep -q -- "--clusters: needs a value" "$T/err"
"$B/sonard" --replay /nonexistent.csv 2> "$T/err" > /dev/null; rc=$?
check "missing file: exit 2, named" sh -c "test $rc -eq 2 && grep -q '/nonexistent.csv: No such file' '$T/err'"
check "--help lists every option with its default" sh -c "'$B/sonard' --help | grep -q -- '--iterations N .*default 10'"

# The activity scene (issue 46): a standing body's echo is steady look to look, a struggling one's is not, as the
# AquaScan recordings' window correlation says (tests/sim_activity.py); the truth names each one's activity.
"$B/sonar-sim" --scene activity --out "$T/activity.csv" --truth "$T/activity.json" > /dev/null 2>&1
check "sonar-sim --scene activity: the stander's echo window correlates look to look above 0.37, the struggler's below 0.32" \
    python3 tests/sim_activity.py "$T/activity.csv" "$T/activity.json"
check "sonar-sim --scene activity: the truth says each person's activity (moving, standing, struggling)" \
    sh -c "grep -q '\"activity\":\"moving\"' '$T/activity.json' && grep -q '\"activity\":\"standing\"' '$T/activity.json' && grep -q '\"activity\":\"struggling\"' '$T/activity.json'"
# sonard's activity on it, as a pool would run it: the empty site surveyed first (the stander is there and
# motionless from the first ping: without a survey nothing tells it from the site), then each seed's pool.
# The activity scene (full turns), the occupied pool (the AquaScan recordings' statistics: a back-and-forth sector at
# 3 gradians, whose passes a gradian apart see a standing body through its 2-degree beam) and the laps pool.
for run in activity:1 activity:2 activity:3 activity:4 activity:5 occupied:1 occupied:2 occupied:3 occupied:4 occupied:5 laps:1 laps:2; do
    sc=${run%%:*}; seed=${run#*:}
    "$B/sonar-sim" --scene "$sc" --seed "$seed" --out "$T/act.csv" --truth "$T/act.json" > /dev/null 2>&1
    "$B/sonar-sim" --scene "$sc" --empty --seed $((seed + 50)) --sweeps 20 --out "$T/act_e.csv" --truth "$T/x.json" > /dev/null 2>&1
    rm -f "$T/act.sv"
    "$B/sonard" --replay "$T/act_e.csv" --survey 20 --survey "$T/act.sv" --quiet --log-level warn > /dev/null
    "$B/sonard" --replay "$T/act.csv" --survey "$T/act.sv" --json --quiet --still-alarm 60 > "$T/act.jsonl" 2> "$T/act$sc$seed.err"
    check "activity, simulated $sc pool seed $seed: >= 75 % of person-sweeps covered, standing vs struggling right, the struggler alarmed by its 4th look, no one else alarmed" \
        python3 tools/eval/activity.py "$T/act.json" "$T/act.jsonl" --check --sim --label "$sc $seed: "
done
sed 's/^/    /' "$T/out"
check "... the struggle alarm said once on stderr with the track and where, the stander's still alarm (--still-alarm 60) too" \
    sh -c "test \$(grep -c 'alarm: track [0-9]*: struggle alarm raised at sweep [0-9]*, at x' '$T/actactivity1.err') -eq 1 &&
           grep -q 'alarm: track [0-9]*: still alarm raised' '$T/actactivity1.err' || { cat '$T/actactivity1.err'; exit 1; }"

echo "e2e: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
