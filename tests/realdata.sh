#!/bin/sh
# realdata.sh -- converters and replay on the real Ping360 recordings in ../shared/data/real (read there, never copied).
# Skips, saying why, when ../shared is absent. Ends with "N passed, N failed".
set -u
B=${1:-build}
R=${SONARD_REAL_DATA:-../shared/data/real}
if [ ! -d "$R/aquascan" ] || [ ! -f "$R/pingviewer_noah/test_ping_log.decoded" ]; then
    echo "realdata: SKIPPED: $R is absent (the real recordings are not in this repository: licence unclear)"
    echo "realdata: 0 passed, 0 failed, 1 skipped"
    exit 0
fi
T=$(mktemp -d /tmp/sonard-real.XXXXXX)
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"

# Ping Viewer .bin -> CSV: a log built from the real noah beams, frame-unaligned chunks, junk first.
for enc in utf16 utf8; do
    n=$(python3 tests/make_pvbin.py "$R/pingviewer_noah/test_ping_log.decoded" "$T/20220822-200542039.bin" \
        $( [ $enc = utf8 ] && echo --utf8 ) --tools "$R/tools")
    "$B/sonar-pvbin2csv" "$T/20220822-200542039.bin" "$T/noah.csv" 2> "$T/pv.err"
    check "Ping Viewer .bin ($enc) -> CSV: all $n real beams recovered, samples identical, times the log's milliseconds" python3 - "$R" "$T/noah.csv" <<'PY'
import sys, csv
sys.path.insert(0, sys.argv[1] + "/tools")
import parse_pingviewer_decoded as p
want = [r for r in p.rows(sys.argv[1] + "/pingviewer_noah/test_ping_log.decoded") if r.get("consistent")]
got = list(csv.reader(open(sys.argv[2])))
assert len(got) == len(want), (len(got), len(want))
for w, g in zip(want, got):
    assert int(g[2]) == w["angle"]
    assert bytes(int(x) for x in g[3].split()) == w["samples"]
    assert "sample_period=%d" % w["sample_period"] in g
    assert int(g[1]) % 1000000 == 0, ("rounded to the millisecond", g[:2])
print(len(got), "beams match")
PY
done
check "the converted Ping Viewer log replays (2 m range from its metadata)" sh -c "'$B/sonard' --replay '$T/noah.csv' --quiet --json | grep -c sweep | grep -qx 2"
head -c 5000 "$T/20220822-200542039.bin" > "$T/cut.bin"
"$B/sonar-pvbin2csv" "$T/cut.bin" "$T/cut.csv" 2> "$T/cut.err"
check "a truncated .bin: named record and byte, the beams before it kept" sh -c "grep -q 'truncated at byte' '$T/cut.err' && test -s '$T/cut.csv'"

# brping's own form, as a new user would try it: 'angle;s0;...' rows under a header, no timestamps.
J=$(ls "$R"/junayed_sector/*_Results.csv 2>/dev/null | head -1)
if [ -n "$J" ]; then
    "$B/sonard" --replay "$J" --json --no-lcm > "$T/jun.jsonl" 2> "$T/jun.err"
    check "brping capture (angle;samples, untimed): the form named, all 101 rows one 100-gradian sweep, timed by the model" \
        python3 - "$T/jun.jsonl" "$T/jun.err" <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
err = open(sys.argv[2]).read()
assert "brping rows (angle;samples" in err and "Ping360 model" in err, err
assert "101 rows used, 0 skipped, 1 sweeps" in err, err
assert len(lines) == 1 and lines[0]["beams"] == 101, lines
# 100 steps of one gradian at 2 m: 19.4 + 6 + 2*2/1500 s = 28.07 ms a beam
assert abs(lines[0]["utime"] - 100 * 28067) < 1000, lines[0]["utime"]
print("1 sweep of", lines[0]["beams"], "beams, last at", lines[0]["utime"] / 1e6, "s")
PY
    "$B/sonard" --replay "$J" --json --no-lcm --quiet --log-level warn --beam-ms 50 > "$T/jun50.jsonl"
    check "brping capture with --beam-ms 50: the sweep ends at 5 s" \
        python3 -c "import json,sys; l=[json.loads(x) for x in open(sys.argv[1])]; assert l[0]['utime']==5000000, l[0]['utime']" "$T/jun50.jsonl"
else
    echo "realdata: brping capture absent from $R/junayed_sector: its checks skipped"
fi

# AquaScan text matrices + labels -> CSV + truth.
python3 tools/data/aquascan2csv.py "$R/aquascan" --out "$T/aq" --range 15 > "$T/aq.out"
check "AquaScan -> CSV: 51 sweeps and 237 labelled people (2 sweeps have no label file)" sh -c "grep -q 'sonar4: 30 sweeps (0 without labels, not scored), 146' '$T/aq.out' && grep -q 'sonar11: 21 sweeps (2 without labels, not scored), 91' '$T/aq.out'"
for s in sonar4 sonar11; do
    "$B/sonard" --replay "$T/aq/$s.csv" --json --quiet --log-level warn > "$T/$s.jsonl"
    check "AquaScan $s replays with one sonard sweep per recorded sweep" \
        test "$(wc -l < "$T/$s.jsonl")" -eq "$(python3 -c "import json;print(len(json.load(open('$T/aq/$s.truth.json'))['sweeps']))")"
done

# The occupied-pool preset: tuned on sonar4, sonar11 held out. The F1 floors guard against regressions
# (measured 0.874 and 0.835 when the preset was chosen; sonar11 0.818 since the tracker's manoeuvre
# pass, whose tracks steer the detection hysteresis: one person fewer found, tracking IDF1 0.538 -> 0.556).
PRESET=docs/presets/occupied-pool.conf
for s in sonar4:0.85 sonar11:0.80; do
    n=${s%%:*}; f=${s#*:}
    "$B/sonard" --replay "$T/aq/$n.csv" --json --quiet --log-level warn --config $PRESET > "$T/$n.preset.jsonl"
    check "AquaScan $n, occupied-pool preset: F1 >= $f" \
        python3 tools/eval/score.py "$T/aq/$n.truth.json" "$T/$n.preset.jsonl" --min-f1 "$f" --label "$n: "
    sed 's/^/    /' "$T/out"
    cp "$T/out" "$T/$n.score"
done
check "AquaScan, both recordings (237 people), occupied-pool preset: F1 >= 0.85" python3 - "$T/sonar4.score" "$T/sonar11.score" <<'PY'
import re, sys
tp = fp = fn = 0
for path in sys.argv[1:]:
    m = re.search(r"\(TP (\d+) FP (\d+) FN (\d+)", open(path).read())
    tp, fp, fn = tp + int(m[1]), fp + int(m[2]), fn + int(m[3])
f1 = 2 * tp / (2 * tp + fp + fn)
print(f"TP {tp} FP {fp} FN {fn}: F1 {f1:.3f}")
assert f1 >= 0.85, f1
PY
sed 's/^/    /' "$T/out"

# sonard's default configuration, no --config (issue 23), at the recorder's 15 m and the batch
# script's 13 m (the range is not in the files). Regression floors under today's figures (15 m:
# 0.732 and 0.641; 13 m: 0.681 and 0.644; the far swimmers, persons 5 and 10, in 16 of 26 and 11 of
# 16 sweeps): the issue's 0.90 and 80 % are not met (docs/results.md). sonar11 is held out: tuned on
# nothing, scored here.
python3 tools/data/aquascan2csv.py "$R/aquascan" --out "$T/aq13" --range 13 > /dev/null
for s in sonar4:15:0.70:5:0.55 sonar4:13:0.65:5:0.55 sonar11:15:0.60:10:0.60 sonar11:13:0.60:10:0.60; do
    n=$(echo "$s" | cut -d: -f1); rng=$(echo "$s" | cut -d: -f2); f=$(echo "$s" | cut -d: -f3)
    who=$(echo "$s" | cut -d: -f4); share=$(echo "$s" | cut -d: -f5)
    d=$T/aq; [ "$rng" = 13 ] && d=$T/aq13
    "$B/sonard" --replay "$d/$n.csv" --json --quiet --log-level warn > "$T/$n.default$rng.jsonl"
    check "AquaScan $n at $rng m, default configuration: F1 >= $f, person $who found in >= $share of their sweeps" \
        python3 tools/eval/score.py "$d/$n.truth.json" "$T/$n.default$rng.jsonl" --min-f1 "$f" --object "$who" \
        --min-found "$share" --label "$n@$rng m: "
    sed 's/^/    /' "$T/out"
done

# What each person is doing (issue 46): the thresholds were fixed on sonar4 (and the simulator), so sonar4 is held to
# the issue's targets under the default configuration and the occupied-pool preset; sonar11 is held out: reported,
# never a gate. Both recordings are the same minutes of probably the same five people: one struggle episode, twice.
for cfg in default preset; do
    j=$T/sonar4.default15.jsonl; [ "$cfg" = preset ] && j=$T/sonar4.preset.jsonl
    check "AquaScan sonar4, $cfg: activity covers >= 75 %, standing vs struggling >= 0.9 (<= 5 % of standing called struggling), moving >= 85 %, the struggler alarmed by its 4th look" \
        python3 tools/eval/activity.py "$T/aq/sonar4.truth.json" "$j" --check --label "sonar4 $cfg: "
    sed 's/^/    /' "$T/out"
    j=$T/sonar11.default15.jsonl; [ "$cfg" = preset ] && j=$T/sonar11.preset.jsonl
    python3 tools/eval/activity.py "$T/aq/sonar11.truth.json" "$j" --label "sonar11 (held out) $cfg: " | sed 's/^/    /'
done

# Real water with nobody in it (issue 51): each recording with its labelled people taken out. sonar4 is the tuning
# recording, held to floors under what was measured (docs/results.md section 12: by hit counts 4.23 tracks a sweep and
# 3 alarms, by existence 0.57 and 1; the issue's 0.3 and 0 are not met); sonar11 is held out: reported, never a gate.
for s in sonar4 sonar11; do
    python3 tools/eval/empty_site.py make "$T/aq/$s.csv" "$T/aq/$s.truth.json" --out "$T/aq/$s.empty" > "$T/$s.empty.out"
done
check "empty_site.py: the labelled people are taken out (detections within 1 m of them: under a fifth of the recording's)" \
    python3 - "$B/sonard" "$T/aq/sonar4" <<'PY'
import json, math, subprocess, sys
B, base = sys.argv[1], sys.argv[2]
truth = json.load(open(base + ".truth.json"))
def near(csv):
    out = subprocess.run([B, "--replay", csv, "--json", "--quiet", "--log-level", "error"], capture_output=True, text=True,
                         check=True).stdout.splitlines()
    n = 0
    for line, sw in zip(out, truth["sweeps"]):
        d = json.loads(line)
        n += sum(1 for o in sw["objects"] for x in d["detections"] if math.hypot(x["x_m"] - o["x"], x["y_m"] - o["y"]) < 1.0)
    return n
full, empty = near(base + ".csv"), near(base + ".empty.csv")
print(f"detections within 1 m of a labelled person: {full} recorded, {empty} emptied")
assert empty * 5 < full, (full, empty)
PY
sed 's/^/    /' "$T/out"
for mode in hits:4.5:3 existence:0.7:1; do
    m=${mode%%:*}; rest=${mode#*:}; mt=${rest%%:*}; ma=${rest#*:}
    "$B/sonard" --replay "$T/aq/sonar4.empty.csv" --json --quiet --log-level error --track-life "$m" > "$T/s4e.$m.jsonl"
    check "AquaScan sonar4 emptied, --track-life $m: <= $mt confirmed tracks a sweep (static since start aside), <= $ma alarms" \
        python3 tools/eval/empty_site.py count "$T/s4e.$m.jsonl" --max-tracks "$mt" --max-alarms "$ma" --label "sonar4 emptied, $m: "
    sed 's/^/    /' "$T/out"
    "$B/sonard" --replay "$T/aq/sonar11.empty.csv" --json --quiet --log-level error --track-life "$m" > "$T/s11e.$m.jsonl"
    python3 tools/eval/empty_site.py count "$T/s11e.$m.jsonl" --label "sonar11 (held out) emptied, $m: " | sed 's/^/    /'
done
"$B/sonard" --replay "$T/aq/sonar4.csv" --json --quiet --log-level error --track-life existence > "$T/s4.exist.jsonl"
check "AquaScan sonar4, --track-life existence: IDF1 >= 0.62 (0.643 measured; hit counts 0.509), the struggler alarmed by its 4th look" \
    sh -c "python3 tools/eval/score.py '$T/aq/sonar4.truth.json' '$T/s4.exist.jsonl' --tracks --min-idf1 0.62 --label 'sonar4 existence: ' && python3 tools/eval/activity.py '$T/aq/sonar4.truth.json' '$T/s4.exist.jsonl' | grep -q 'struggler 3: struggle alarm first at its labelled look [1-4] of'"
sed 's/^/    /' "$T/out"
# The survey's "someone moved" check judges tracks that exist: over the emptied first 16 sweeps it is kept, and carries
# the clutter map learnt over them (said when loaded); over the occupied ones, where two people swim, it is refused.
"$B/sonard" --replay "$T/aq/sonar4.empty.csv" --quiet --log-level warn --survey 16 --survey "$T/s4e.sv" 2> "$T/s4e.sv.err"
"$B/sonard" --replay "$T/aq/sonar4.csv" --quiet --log-level warn --survey 16 --survey "$T/s4.sv" 2> "$T/s4.sv.err"
check "AquaScan sonar4: --survey 16 kept over the emptied sweeps, refused over the occupied ones (someone moved)" \
    sh -c "grep -q 'survey: written to' '$T/s4e.sv.err' && test -s '$T/s4e.sv' && grep -q 'refused, nothing written: track .* someone or something was in the water' '$T/s4.sv.err' && test ! -e '$T/s4.sv'"
"$B/sonard" --replay "$T/aq/sonar4.empty.csv" --json --quiet --log-level info --survey "$T/s4e.sv" > "$T/s4e.sv.jsonl" 2> "$T/s4e.use.err"
check "the survey carries its clutter map: loaded and said; the emptied sweeps after it raise no alarm" \
    sh -c "grep -q 'clutter map: loaded, learnt over' '$T/s4e.use.err' && python3 tools/eval/empty_site.py count '$T/s4e.sv.jsonl' --sweeps 16: --max-alarms 0 --label 'sonar4 emptied, surveyed, from sweep 16: '"
sed 's/^/    /' "$T/out"
# Hybrid scenes (sonar-sim --water): the simulated occupied pool's five people drawn on emptied sonar4, nothing else
# changed; found there as docs/results.md section 12 measures (F1 0.744 by the default; floor under it).
"$B/sonar-sim" --scene occupied --water "$T/aq/sonar4.empty.csv" --out "$T/hy4.csv" --truth "$T/hy4.json"
"$B/sonard" --replay "$T/hy4.csv" --json --quiet --log-level error > "$T/hy4.jsonl"
check "hybrid: the occupied scene's people on emptied sonar4, nothing else changed, sonard's sweeps the truth's; F1 >= 0.70" \
    sh -c "python3 tests/water_check.py '$T/aq/sonar4.empty.csv' '$T/hy4.csv' '$T/hy4.json' --sweeps-from '$T/hy4.jsonl' && python3 tools/eval/score.py '$T/hy4.json' '$T/hy4.jsonl' --tracks --min-f1 0.70 --label 'hybrid on sonar4: '"
sed 's/^/    /' "$T/out"
# The simulator's transients (sonar-sim --transients), calibrated on emptied sonar4: the empty occupied pool's
# default detections a sweep within 30 % of the emptied recording's, over three seeds (issue 51).
"$B/sonard" --replay "$T/aq/sonar4.empty.csv" --json --quiet --log-level error > "$T/s4e.default.jsonl"
for seed in 1 2 3; do
    "$B/sonar-sim" --scene occupied --empty --transients --seed $seed --out "$T/tr$seed.csv" --truth "$T/tr$seed.json"
    "$B/sonard" --replay "$T/tr$seed.csv" --json --quiet --log-level error > "$T/tr$seed.jsonl"
done
check "sonar-sim --transients: the simulated empty pool's false objects a sweep within 30 % of emptied sonar4's" python3 - "$T" <<'PY'
import json, subprocess, sys
T = sys.argv[1]
def per(j):
    return json.loads(subprocess.run([sys.executable, "tools/eval/transients.py", j, "--json"], capture_output=True,
                                     text=True, check=True).stdout)["detections_a_sweep"]
real = per(f"{T}/s4e.default.jsonl")
sim = sum(per(f"{T}/tr{s}.jsonl") for s in (1, 2, 3)) / 3
print(f"false objects a sweep: emptied sonar4 {real:.2f}, simulated with transients {sim:.2f} (ratio {sim / real:.2f})")
assert abs(sim / real - 1.0) <= 0.3, (sim, real)
PY
sed 's/^/    /' "$T/out"

# Live and streaming: sonar4 served by sonar-feed as a Ping360 over TCP (127.0.0.1), driven by
# sonard --sonar over the same back-and-forth sector: the same detections as the replay.
port=$((30000 + $$ % 20000))
"$B/sonar-feed" --listen tcp:127.0.0.1:$port --csv "$T/aq/sonar4.csv" --range 15 --pace fast \
    --max-seconds 60 --exit-after-motor-off > "$T/feed.log" 2>&1 &
fpid=$!
sleep 0.3
# --track off on both sides: the tracker predicts with each beam's time, and live beams (--pace fast)
# are stamped on arrival, not with the recording's times, so its track_m gate would move.
timeout 60 "$B/sonard" --sonar tcp:127.0.0.1:$port --no-lcm --range 15 --samples 500 --sector 100:300 --step 3 \
    --sweeps 30 --json --quiet --config $PRESET --track off > "$T/live4.jsonl" 2> "$T/live4.err"
wait $fpid 2>/dev/null
"$B/sonard" --replay "$T/aq/sonar4.csv" --json --quiet --log-level warn --config $PRESET --track off > "$T/sonar4.off.jsonl"
check "AquaScan sonar4 live through sonar-feed (TCP, sector 100:300, step 3): the replay's detections" python3 - "$T/live4.jsonl" "$T/sonar4.off.jsonl" <<'PY'
import json, sys
a = [json.loads(l) for l in open(sys.argv[1])]
b = [json.loads(l) for l in open(sys.argv[2])]
assert len(a) == len(b) == 30, (len(a), len(b))
# The recording stops one beam before its last reversal; live, the driver's 30th sweep gets that beam.
# Live beams are stamped on arrival, replayed ones with the recording's times: everything but "utime" must agree.
strip = lambda ds: [{k: v for k, v in d.items() if k != "utime"} for d in ds]
for x, y in zip(a[:-1], b[:-1]):
    assert x["beams"] == y["beams"] and strip(x["detections"]) == strip(y["detections"]), x["sweep"]
assert a[-1]["beams"] == b[-1]["beams"] + 1
print(len(a) - 1, "sweeps,", sum(len(x["detections"]) for x in a[:-1]), "detections identical")
PY
echo "realdata: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
