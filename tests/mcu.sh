#!/bin/sh
# mcu.sh -- the co-processor firmware in QEMU (mps2-an500): sonar-feed serves a scene over TCP to UART0, UART1 goes to
# sonard --coprocessor; detections must equal --replay of the beams the firmware forwarded. Then a faulty sonar.
# Loopback only, every run bounded in time. Usage: sh tests/mcu.sh BUILD_DIR. Ends with "N passed, N failed".
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-mcu.XXXXXX)
PORT=$(( 21000 + ($$ % 19000) ))
PIDS=""
trap 'for p in $PIDS; do kill $p 2>/dev/null; done; rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
ELF="$B/mcu/sonard-an500.elf"
MACHINE=mps2-an500
# A co-processor that refuses the configuration: sonard says why and exits 2 (no QEMU needed).
fp=$PORT; PORT=$((PORT + 1))
python3 tests/fake_coproc.py "$fp" & pp=$!
sleep 0.5
timeout 30 "$B/sonard" --coprocessor "tcp:127.0.0.1:$fp" --no-lcm --json > /dev/null 2> "$T/refused.err"; rc=$?
kill $pp 2>/dev/null; wait $pp 2>/dev/null
check "a refused configuration: sonard --coprocessor says why and exits 2" \
    sh -c "test $rc -eq 2 && grep -q 'refused the configuration: error: detector.track_points' '$T/refused.err'"

# SIGHUP with a co-processor: the firmware runs the detector, so it gets the new configuration too (no QEMU needed:
# a stand-in that accepts every configuration and logs what it was sent).
fp=$PORT; PORT=$((PORT + 1))
printf 'range = 12\nmin-points = 20\n' > "$T/hup.conf"
python3 tests/fake_coproc.py "$fp" --accept "$T/hup.configs" --types "$B/lcm/python" & pp=$!
sleep 0.5
"$B/sonard" --coprocessor "tcp:127.0.0.1:$fp" --config "$T/hup.conf" --no-lcm --json > /dev/null 2> "$T/hup.err" & sp=$!
nlines() { if [ -f "$1" ]; then wc -l < "$1"; else echo 0; fi; }
i=0; while [ "$(nlines "$T/hup.configs")" -lt 1 ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
printf 'range = 12\nmin-points = 30\nangle-offset = 100\n' > "$T/hup.conf"
kill -HUP $sp
i=0; while [ "$(nlines "$T/hup.configs")" -lt 2 ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
sleep 0.3
kill -TERM $sp; wait $sp; rc=$?
kill $pp 2>/dev/null; wait $pp 2>/dev/null
check "SIGHUP with a co-processor: the new detector settings are sent to it (min-points 20 -> 30, angle-offset 0 -> 100), accepted" \
    python3 -c "
import json, sys
c = [json.loads(l) for l in open('$T/hup.configs')]
print(c)
assert len(c) == 2 and (c[0]['min_points'], c[1]['min_points']) == (20, 30), c
assert abs(c[1]['angle_offset'] - 100) < 1e-6 and c[0]['range_m'] == c[1]['range_m'] == 12.0, c
assert 'configuration accepted (SIGHUP)' in open('$T/hup.err').read() and $rc == 0"
sed 's/^/    /' "$T/out"

if ! command -v qemu-system-arm >/dev/null 2>&1; then
    echo "mcu: SKIPPED: qemu-system-arm is not installed (make deps installs it)"
    echo "mcu: $pass passed, $fail failed, 1 skipped"
    exit 0
fi
types="$B/lcm/python"
# The options both the firmware (pushed to it) and the replay use. A sector and 200 samples keep QEMU's
# ~12 KiB/s UART quick enough: about 5 s a sweep.
OPTS="--range 12 --samples 200 --sector 100:300 --step 2"
# The F405's own grid with no detector option given: what a user runs (issue 44).
DEFAULT_OPTS="--range 12 --samples 500 --step 2 --sector 100:300"

FEED="--scene pool"
# run NAME SWEEPS [feed options...]: feed ($FEED) -> QEMU UART0; QEMU UART1 -> sonard --coprocessor.
run() {
    name=$1 sweeps=$2; shift 2
    p0=$PORT p1=$((PORT + 1)); PORT=$((PORT + 2))
    # shellcheck disable=SC2086 # FEED: the feeder's source, words
    "$B/sonar-feed" --listen "tcp:127.0.0.1:$p0" $FEED --pace fast --log "$T/$name.feed" --max-seconds 150 "$@" \
        2> /dev/null & fp=$!
    sleep 0.3
    qemu-system-arm -M "$MACHINE" -display none -monitor none -kernel "$ELF" \
        -serial "tcp:127.0.0.1:$p0,reconnect=1" -serial "tcp:127.0.0.1:$p1,server=on,wait=off" \
        > "$T/$name.qemu" 2>&1 & qp=$!
    PIDS="$fp $qp"
    sleep 0.5
    # shellcheck disable=SC2086
    timeout "${RUN_TIMEOUT:-140}" "$B/sonard" --coprocessor "tcp:127.0.0.1:$p1" $OPTS --sweeps "$sweeps" --json \
        --lcm "file://$T/$name.lcm?mode=w" --coprocessor-beams 1 --csv-out "$T/$name.csv" \
        > "$T/$name.jsonl" 2> "$T/$name.err"; rc=$?
    kill $qp $fp 2>/dev/null; wait $qp $fp 2>/dev/null; PIDS=""
}

cmp_replay() {
    # The rows carry the range the device gave (range_m=, from its sample period): --range would override it.
    # shellcheck disable=SC2086
    "$B/sonard" --replay "$T/$1.csv" $(echo "$OPTS" | sed 's/--range [0-9.]*//') --json --quiet --log-level warn > "$T/$1.replay.jsonl"
    python3 tests/mcu_equal.py "$T/$1.jsonl" "$T/$1.replay.jsonl"
}

run clean 4
check "clean: sonard --coprocessor exits 0 after --sweeps 4" sh -c "test $rc -eq 0 && test \$(wc -l < '$T/clean.jsonl') -eq 4"
check "clean: the firmware accepted the pushed configuration" grep -q "configuration accepted" "$T/clean.err"
check "clean: detections equal --replay of the beams the firmware forwarded" cmp_replay clean
sed 's/^/    /' "$T/out"
check "clean: the scene's objects are found (some sweep has a detection)" grep -q x_m "$T/clean.jsonl"
check "clean: no corrupt or undecodable frame on the host link" grep -q "crc_errors 0 .*decode_errors 0" "$T/clean.err"
python3 tools/data/lcm_log.py "$T/clean.lcm" summary --types "$types" > "$T/clean.summary" 2>&1
check "clean: SONAR_DETECTIONS, SONAR_STATUS and SONAR_BEAM republished on LCM" \
    sh -c "grep -q '^SONAR_DETECTIONS 4' '$T/clean.summary' && grep -q '^SONAR_STATUS' '$T/clean.summary' && grep -q '^SONAR_BEAM' '$T/clean.summary'"

# A faulty sonar: drops, corruption, junk, one disconnect (QEMU's UART0 reconnects). The firmware recovers as the host
# does and its counters reach SONAR_STATUS.
run faulty 4 --drop 0.03 --corrupt 0.02 --garbage 0.03 --disconnect-after 150
check "faulty: the firmware keeps detecting: 4 sweeps, exit 0" sh -c "test $rc -eq 0 && test \$(wc -l < '$T/faulty.jsonl') -eq 4"
check "faulty: detections still equal --replay of the forwarded beams" cmp_replay faulty
python3 tools/data/lcm_log.py "$T/faulty.lcm" status --types "$types" > "$T/faulty.status" 2>&1
sed -n 's/^summary //p' "$T/faulty.feed" > "$T/faulty.injected"
check "faulty: the firmware's counters reach SONAR_STATUS (checksum errors, resyncs, timeouts, retries)" \
    python3 - "$T/faulty.status" "$T/faulty.injected" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
w = open(sys.argv[2]).read().split()
f = {w[i]: int(w[i + 1]) for i in range(0, len(w), 2)}
print("firmware:", {k: s[k] for k in ("checksum_errors", "resyncs", "timeouts", "retries", "reconnects", "beams", "stack_used")})
print("injected:", {k: f[k] for k in ("dropped", "corrupted", "garbage", "disconnects")})
assert s["checksum_errors"] >= 1 and s["timeouts"] >= 1 and s["retries"] >= 1 and s["resyncs"] >= 1
assert f["disconnects"] == 1 and s["beams"] > 0
PY
sed 's/^/    /' "$T/out"

# The same firmware laid out in an STM32H743's banks (src/mcu/h743.ld: DTCM 128 KiB with an 8 KiB stack, the background in
# the 512 KiB AXI SRAM), on the same QEMU board.
# On the default detector options (none given) at 500 samples and 2-gradian steps, over the pool's objects appearing:
# the scene issue 44 reported the F405 differing on (here and on the F405 below).
ELF="$B/mcu/sonard-an500-h743.elf"
OPTS_KEPT=$OPTS
OPTS=$DEFAULT_OPTS
run h743 6
check "H743 banks, default detector options at 500 samples: the firmware runs, 6 sweeps, exit 0" \
    sh -c "test $rc -eq 0 && test \$(wc -l < '$T/h743.jsonl') -eq 6"
check "H743 banks, default detector options: detections equal --replay of the beams the firmware forwarded" cmp_replay h743
sed 's/^/    /' "$T/out"
OPTS=$OPTS_KEPT
python3 tools/data/lcm_log.py "$T/h743.lcm" status --types "$types" > "$T/h743.status" 2>&1
check "H743 banks: the painted stack stays within its 8 KiB (stack_used on SONAR_STATUS)" python3 -c \
    "import json, sys; s = json.load(open(sys.argv[1])); print('stack_used', s['stack_used'], 'B'); assert 0 < s['stack_used'] <= 8192" \
    "$T/h743.status"
sed 's/^/    /' "$T/out"

# The second board: an STM32F405 (Cortex-M4F) in QEMU's netduinoplus2, USART1 to the sonar and USART2 to the host (the
# same command line shape: first -serial, second -serial), built for 200 angles x 500 samples.
ELF="$B/mcu/sonard-f405.elf"
MACHINE=netduinoplus2
run f405 3
check "STM32F405: the firmware runs, 3 sweeps, exit 0" sh -c "test $rc -eq 0 && test \$(wc -l < '$T/f405.jsonl') -eq 3"
check "STM32F405: the firmware accepted the pushed configuration" grep -q "configuration accepted" "$T/f405.err"
check "STM32F405: detections equal --replay of the beams the firmware forwarded" cmp_replay f405
sed 's/^/    /' "$T/out"
python3 tools/data/lcm_log.py "$T/f405.lcm" status --types "$types" > "$T/f405.status" 2>&1
check "STM32F405: the painted stack stays within its 8 KiB (stack_used on SONAR_STATUS)" python3 -c \
    "import json, sys; s = json.load(open(sys.argv[1])); print('stack_used', s['stack_used'], 'B'); assert 0 < s['stack_used'] <= 8192" \
    "$T/f405.status"
sed 's/^/    /' "$T/out"
# The F405's own grid: 500 samples at 2-gradian steps with --min-points 10, over the pool's posts and buoy appearing
# (sweeps 2 and 3): a scene a review found the F405 differing from the replay on (docs/coprocessor.md).
OPTS_KEPT=$OPTS
OPTS="--range 12 --samples 500 --step 2 --min-points 10 --sector 100:300"
run f405b 6
check "STM32F405 at 500 samples, 2-gradian steps, --min-points 10, objects appearing: 6 sweeps, exit 0" \
    sh -c "test $rc -eq 0 && test \$(wc -l < '$T/f405b.jsonl') -eq 6"
check "STM32F405 at 500 samples: detections equal --replay of the beams the firmware forwarded" cmp_replay f405b
sed 's/^/    /' "$T/out"
OPTS=$DEFAULT_OPTS
run f405d 6
check "STM32F405, default detector options at 500 samples: 6 sweeps, exit 0" \
    sh -c "test $rc -eq 0 && test \$(wc -l < '$T/f405d.jsonl') -eq 6"
check "STM32F405, default detector options: detections equal --replay of the beams the firmware forwarded" cmp_replay f405d
sed 's/^/    /' "$T/out"
OPTS=$OPTS_KEPT
# A configuration for a bigger grid than the board was built for: refused by name, sonard exits 2.
p0=$PORT p1=$((PORT + 1)); PORT=$((PORT + 2))
"$B/sonar-feed" --listen "tcp:127.0.0.1:$p0" --scene pool --pace fast --max-seconds 30 2> /dev/null & fp=$!
sleep 0.3
qemu-system-arm -M netduinoplus2 -display none -monitor none -kernel "$ELF" -serial "tcp:127.0.0.1:$p0,reconnect=1" \
    -serial "tcp:127.0.0.1:$p1,server=on,wait=off" > "$T/big.qemu" 2>&1 & qp=$!
PIDS="$fp $qp"
sleep 0.5
timeout 30 "$B/sonard" --coprocessor "tcp:127.0.0.1:$p1" --range 12 --samples 600 --no-lcm --json > /dev/null 2> "$T/big.err"; rc=$?
kill $qp $fp 2>/dev/null; wait $qp $fp 2>/dev/null; PIDS=""
check "STM32F405: 600 samples (its build takes 500) refused by name, sonard exits 2" \
    sh -c "test $rc -eq 2 && grep -q 'samples: 200..500 on this board' '$T/big.err'"
ELF="$B/mcu/sonard-an500.elf"
MACHINE=mps2-an500

# Issue 50's case (../shared/data/regress/f405-equal): the beams a stand-in Ping360 served to the F405, 600 samples a
# row, asked for at 500 samples, 2-gradian steps, 15 m, --min-points 10. The F405's reported answer is the host's on
# the beams it was given: the rows at the 500 samples it asked for (a Ping360 answers with the samples asked).
REG=${SONARD_REGRESS:-../shared/data/regress}/f405-equal
if [ -f "$REG/served-beams.csv.gz" ]; then
    gunzip -c "$REG/served-beams.csv.gz" > "$T/served.csv"
    python3 - "$T/served.csv" "$T/served500.csv" <<'PY'
import sys
# Each row at 500 samples over the same range, sample i the row's nearest at or before i * 600 / 500 (as sonar-feed
# answers a recording asked for another number of samples).
with open(sys.argv[2], "w") as out:
    for line in open(sys.argv[1]):
        s, ns, a, v = line.rstrip("\n").split(",", 3)
        v = v.strip('"').split()
        out.write(f"{s},{ns},{a},{' '.join(v[i * len(v) // 500] for i in range(500))}\n")
PY
    "$B/sonard" --replay "$T/served500.csv" --range 15 --min-points 10 --json --quiet --log-level warn > "$T/served500.jsonl"
    "$B/sonard" --replay "$T/served.csv" --range 15 --min-points 10 --json --quiet --log-level warn > "$T/served600.jsonl"
    check "f405-equal: the F405's reported detections are the host's on the beams it asked for (the rows at 500 samples), every sweep: count, cells, centroids within 1 mm" \
        python3 - "$REG/coprocessor-f405.json" "$T/served500.jsonl" "$T/served600.jsonl" <<'PY'
import json, sys
co = json.load(open(sys.argv[1]))["sweeps"]
h5 = {d["sweep"]: d for d in map(json.loads, open(sys.argv[2]))}
h6 = {d["sweep"]: d for d in map(json.loads, open(sys.argv[3]))}
key = lambda ds, x, y: sorted((d[x], d[y], d["points"]) for d in ds)
n6 = 0
for c in co:
    a, b = key(c["detections"], "x", "y"), key(h5[c["sweep"]]["detections"], "x_m", "y_m")
    assert len(a) == len(b), (c["sweep"], a, b)
    for p, q in zip(a, b):
        assert p[2] == q[2] and abs(p[0] - q[0]) <= 0.001 and abs(p[1] - q[1]) <= 0.001, (c["sweep"], p, q)
    n6 += key(c["detections"], "x", "y") == key(h6[c["sweep"]]["detections"], "x_m", "y_m")
print(f"{len(co)} sweeps equal to the host on the rows at 500 samples; {n6} of them equal to the host on the 600-sample rows")
assert n6 < len(co), "the 600-sample rows should differ: the case would not be the one reported"
PY
    sed 's/^/    /' "$T/out"
    # The same served rows through each board, asked for the same settings; each board's detections equal the host's
    # replay of the beams that board was given (sonar-feed answers the 500 samples asked, as the stand-in did).
    OPTS_KEPT=$OPTS
    OPTS="--range 15 --min-points 10 --samples 500 --step 2"
    FEED="--csv $T/served.csv --range 15"
    for board in an500:mps2-an500:sonard-an500 h743:mps2-an500:sonard-an500-h743 f405:netduinoplus2:sonard-f405; do
        bn=${board%%:*}; MACHINE=$(echo "$board" | cut -d: -f2); ELF=$B/mcu/$(echo "$board" | cut -d: -f3).elf
        run "reg-$bn" 4
        check "f405-equal on $bn: 4 sweeps of the served beams, exit 0" \
            sh -c "test $rc -eq 0 && test \$(wc -l < '$T/reg-$bn.jsonl') -eq 4"
        check "f405-equal on $bn: detections equal the host's replay of the beams it was served (count, cells, within 1 mm)" cmp_replay "reg-$bn"
        sed 's/^/    /' "$T/out"
    done
    # A sonar that answers with more samples than asked, and than the F405 holds: never cut to fit; said by name.
    MACHINE=netduinoplus2; ELF=$B/mcu/sonard-f405.elf
    RUN_TIMEOUT=20
    run reg-long 1 --samples-as-recorded
    RUN_TIMEOUT=140
    check "a sonar answering 600 samples to the F405 (it holds 500): said by name, nothing cut to fit or detected" \
        sh -c "grep -q 'co-processor: beam: 600 samples from the sonar, more than this board.s build holds (500' '$T/reg-long.err' &&
               ! grep -q x_m '$T/reg-long.jsonl'"
    # A step finer than the F405's angle cells: refused by name when configured (it would put two beams in a cell).
    OPTS="--range 15 --samples 500 --step 1"
    run reg-step 1
    check "the F405 asked for 1-gradian steps (200 angle cells a turn): refused by name, sonard exits 2" \
        sh -c "test $rc -eq 2 && grep -q 'step: at least 400 gradians / 200 angle cells' '$T/reg-step.err'"
    FEED="--scene pool"
    OPTS=$OPTS_KEPT
    ELF="$B/mcu/sonard-an500.elf"
    MACHINE=mps2-an500
else
    echo "mcu: the f405-equal case SKIPPED: $REG is absent (../shared beside the clone holds it)"
fi

# A bad host: garbage, truncated and corrupt frames, an out-of-range configuration (named, settings kept), then silence.
p0=$PORT p1=$((PORT + 1)); PORT=$((PORT + 2))
"$B/sonar-feed" --listen "tcp:127.0.0.1:$p0" --scene pool --pace fast --max-seconds 60 2> /dev/null & fp=$!
sleep 0.3
qemu-system-arm -M mps2-an500 -display none -monitor none -kernel "$ELF" -serial "tcp:127.0.0.1:$p0,reconnect=1" \
    -serial "tcp:127.0.0.1:$p1,server=on,wait=off" > "$T/bad.qemu" 2>&1 & qp=$!
PIDS="$fp $qp"
sleep 0.5
check "bad host: junk and corrupt frames dropped; an out-of-range value refused by name; a good one accepted; keeps sending" \
    timeout 60 python3 tests/mcu_badhost.py "$p1" --types "$types"
sed 's/^/    /' "$T/out"
kill $qp $fp 2>/dev/null; wait $qp $fp 2>/dev/null; PIDS=""

echo "mcu: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
