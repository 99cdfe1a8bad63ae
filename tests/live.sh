#!/bin/sh
# live.sh -- end to end, live: sonar-feed (a simulated Ping360) -> sonard over TCP, UDP and a pty -> LCM file log,
# scored against the truth; a faulty link; auto mode; SIGTERM. Loopback only, every run bounded in time.
# Usage: sh tests/live.sh BUILD_DIR. Ends with "N passed, N failed".
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-live.XXXXXX)
PORT=$(( 20000 + ($$ % 20000) ))
FEEDPID=""
trap '[ -n "$FEEDPID" ] && kill $FEEDPID 2>/dev/null; rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
types="$B/lcm/python"
"$B/sonar-sim" --scene pool --out "$T/pool.csv" --truth "$T/pool.json" --sweeps 7
"$B/sonar-sim" --scene pool --out "$T/pool5.csv" --truth "$T/pool5.json" --sweeps 5

# feed URL [feed options...]: starts sonar-feed in the background; waits until it listens.
feed() {
    url=$1; shift
    rm -f "$T/feed.log"
    "$B/sonar-feed" --listen "$url" --scene pool --log "$T/feed.log" --max-seconds 120 "$@" 2> "$T/feed.err" &
    FEEDPID=$!
    i=0; while [ $i -lt 50 ] && ! [ -s "$T/feed.log" ] && ! { [ "${url#pty:}" != "$url" ] && [ -e "${url#pty:}" ]; }; do
        # TCP/UDP sockets exist once the process runs; give it a moment
        i=$((i + 1)); sleep 0.05; [ $i -ge 4 ] && [ "${url#pty:}" = "$url" ] && break
    done
}
endfeed() { [ -n "$FEEDPID" ] && { kill $FEEDPID 2>/dev/null; wait $FEEDPID 2>/dev/null; }; FEEDPID=""; }

run_transport() {
    name=$1 url=$2 sonar=$3
    feed "$url" --pace fast --exit-after-motor-off
    timeout 120 "$B/sonard" --sonar "$sonar" --range 12 --sweeps 7 --json --lcm "file://$T/$name.lcm?mode=w" \
        > "$T/$name.jsonl" 2> "$T/$name.err"; rc=$?
    wait $FEEDPID 2>/dev/null; FEEDPID=""
    check "$name: sonard exits 0 after --sweeps 7" test "$rc" -eq 0
    check "$name: exactly 7 sweeps, though a fast device answers before the next read" test "$(wc -l < "$T/$name.jsonl")" -eq 7
    check "$name: detections meet precision/recall >= 0.95, error <= 0.3 m" \
        python3 tools/eval/score.py "$T/pool.json" "$T/$name.jsonl" --min-precision 0.95 --min-recall 0.95 --max-error 0.3
    python3 tools/data/lcm_log.py "$T/$name.lcm" detections --types "$types" > "$T/$name.lcm.jsonl" 2>&1
    check "$name: the same detections come back out of the LCM log" \
        python3 tools/eval/score.py "$T/pool.json" "$T/$name.lcm.jsonl" --min-precision 0.95 --min-recall 0.95
    check "$name: every beam published on SONAR_BEAM" \
        sh -c "python3 tools/data/lcm_log.py '$T/$name.lcm' summary --types '$types' | grep -qE '^SONAR_BEAM (28[0-9][0-9])$'"
    check "$name: motor_off reached the sonar" grep -q "^motor_off" "$T/feed.log"
    if [ "$name" = tcp ]; then
        # LCM log -> CSV -> replay gives the live run's detections again
        python3 tools/data/lcm_log.py "$T/tcp.lcm" beams-csv --types "$types" > "$T/tcp.beams.csv"
        "$B/sonard" --replay "$T/tcp.beams.csv" --json 2>/dev/null | head -7 > "$T/tcp.replayed.jsonl"
        check "tcp: LCM log -> CSV replays to the live detections" cmp "$T/tcp.replayed.jsonl" "$T/tcp.jsonl"
        python3 tools/data/lcm_log.py "$T/tcp.lcm" detections-csv --types "$types" > "$T/tcp.det.csv"
        check "tcp: LCM log -> detections CSV has one row per detection" \
            test "$(($(wc -l < "$T/tcp.det.csv") - 1))" -eq "$(python3 -c "import json,sys;print(sum(len(json.loads(l)['detections']) for l in open('$T/tcp.jsonl')))")"
    fi
}

run_transport tcp "tcp:127.0.0.1:$PORT" "tcp:127.0.0.1:$PORT"
run_transport udp "udp:127.0.0.1:$((PORT + 1))" "udp:127.0.0.1:$((PORT + 1))"
run_transport pty "pty:$T/ttyPing360" "serial:$T/ttyPing360:115200"

# A faulty link: 5 % of replies dropped, 1 % corrupted, garbage before 5 %, one disconnect.
feed "tcp:127.0.0.1:$((PORT + 2))" --pace fast --exit-after-motor-off --drop 0.05 --corrupt 0.01 --garbage 0.05 \
    --disconnect-after 1500
timeout 120 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 2))" --range 12 --sweeps 7 --json \
    --lcm "file://$T/faulty.lcm?mode=w" > "$T/faulty.jsonl" 2> "$T/faulty.err"; rc=$?
wait $FEEDPID 2>/dev/null; FEEDPID=""
check "faulty link: sonard keeps running, reconnects and exits 0" test "$rc" -eq 0
check "faulty link: precision/recall >= 0.9" \
    python3 tools/eval/score.py "$T/pool.json" "$T/faulty.jsonl" --min-precision 0.9 --min-recall 0.9
python3 tools/data/lcm_log.py "$T/faulty.lcm" status --types "$types" > "$T/status.json"
sed -n 's/^summary //p' "$T/feed.log" > "$T/injected"
check "faulty link: status counters match the faults injected" python3 - "$T/status.json" "$T/injected" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
w = open(sys.argv[2]).read().split()
f = {w[i]: int(w[i + 1]) for i in range(0, len(w), 2)}
print("sonard:", {k: s[k] for k in ("checksum_errors", "resyncs", "timeouts", "retries", "reconnects", "beams")})
print("injected:", f)
assert f["dropped"] > 0 and f["corrupted"] > 0 and f["garbage"] > 0 and f["disconnects"] == 1
assert s["checksum_errors"] == f["corrupted"], "every corrupted frame fails its checksum"
assert s["timeouts"] == f["dropped"] + f["corrupted"], "every lost or corrupt reply times out once"
assert s["retries"] == s["timeouts"], "and is retried"
assert s["reconnects"] == f["disconnects"], "one reconnect per disconnect"
assert f["garbage"] <= s["resyncs"] <= f["garbage"] + f["corrupted"], "a resync per garbage run or bad frame"
PY
check "faulty link: no beam from a corrupt frame (beams published = good device_data frames)" \
    sh -c "python3 tools/data/lcm_log.py '$T/faulty.lcm' summary --types '$types' | grep -q \"^SONAR_BEAM \$(python3 -c \"import json;print(json.load(open('$T/status.json'))['beams'])\")\$\""

# A stall: the device goes quiet for 1 s mid-sweep; sonard retries (the re-homing allowance covers it) and goes on.
feed "tcp:127.0.0.1:$((PORT + 7))" --pace fast --exit-after-motor-off --stall-at 300 --stall 1.0
timeout 60 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 7))" --range 12 --sweeps 2 --json --no-lcm \
    > "$T/stall.jsonl" 2> "$T/stall.err"; rc=$?
wait $FEEDPID 2>/dev/null; FEEDPID=""
check "stall of 1 s: sonard retries without reconnecting and finishes" \
    sh -c "test $rc -eq 0 && test \$(wc -l < '$T/stall.jsonl') -eq 2 && grep -q 'timeouts [1-9]' '$T/stall.err' && grep -q 'reconnects 0' '$T/stall.err' && grep -q '^stall_ms 1000' '$T/feed.log'"

# auto_transmit on firmware > 3.3.0, and the fallback to stepping on 3.3.0.
feed "tcp:127.0.0.1:$((PORT + 3))" --pace fast --exit-after-motor-off --firmware 3.3.8
timeout 60 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 3))" --range 12 --sweeps 5 --mode auto --json --no-lcm \
    > "$T/auto.jsonl" 2> "$T/auto.err"; rc=$?
wait $FEEDPID 2>/dev/null; FEEDPID=""
check "auto mode: streams auto_device_data and exits 0" sh -c "test $rc -eq 0 && grep -q 'scanning (auto_transmit)' '$T/auto.err'"
check "auto mode: detections meet precision/recall >= 0.95" \
    python3 tools/eval/score.py "$T/pool5.json" "$T/auto.jsonl" --min-precision 0.95 --min-recall 0.95
feed "tcp:127.0.0.1:$((PORT + 4))" --pace fast --exit-after-motor-off --firmware 3.3.0
timeout 60 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 4))" --range 12 --sweeps 1 --mode auto --no-lcm --json \
    > /dev/null 2> "$T/fallback.err"
wait $FEEDPID 2>/dev/null; FEEDPID=""
check "auto mode on firmware 3.3.0 falls back to stepping" grep -q "scanning (stepping)" "$T/fallback.err"

# A config file, a flag overriding it, and a live recording that replays.
printf '# sonard test config\nrange = 12\nsweeps = 7\nmode = step\njson = true\nno-lcm = yes\n' > "$T/sonard.conf"
feed "tcp:127.0.0.1:$((PORT + 5))" --pace fast --exit-after-motor-off
timeout 60 "$B/sonard" --config "$T/sonard.conf" --sweeps 3 --sonar "tcp:127.0.0.1:$((PORT + 5))" --csv-out "$T/rec.csv" \
    > "$T/conf.jsonl" 2> "$T/conf.err"; rc=$?
wait $FEEDPID 2>/dev/null; FEEDPID=""
check "config file read, --sweeps 3 overrides its 7" sh -c "test $rc -eq 0 && test \$(wc -l < '$T/conf.jsonl') -eq 3"
check "--csv-out records raw beams with metadata columns" grep -q 'range_m=11.9925,gain=0,sample_period=533,transmit_duration=64,transmit_frequency=750,speed_of_sound=1500.0' "$T/rec.csv"
"$B/sonard" --replay "$T/rec.csv" --json 2>/dev/null | head -3 > "$T/rec.jsonl"
check "the live recording replays to the same detections" cmp "$T/rec.jsonl" "$T/conf.jsonl"

# SIGHUP: the --config file is re-read; detector settings change at the next sweep, the link stays up;
# a bad file is named with its line and the running settings stay.
lines() { wc -l < "$1" 2>/dev/null || echo 0; }
waitlines() { i=0; while [ "$(lines "$1")" -lt "$2" ] && [ $i -lt 200 ]; do sleep 0.05; i=$((i + 1)); done; }
printf 'range = 12\nmin-points = 20\n' > "$T/hup.conf"
feed "tcp:127.0.0.1:$((PORT + 8))" --pace fast
# Not under timeout(1), which forwards only the first SIGHUP; a watchdog bounds it instead.
"$B/sonard" --config "$T/hup.conf" --sonar "tcp:127.0.0.1:$((PORT + 8))" --json --no-lcm \
    > "$T/hup.jsonl" 2> "$T/hup.err" & SPID=$!
( sleep 60; kill -KILL $SPID ) > /dev/null 2>&1 & WDOG=$! # its sleep, orphaned by the kill below, must not hold a pipe
waitlines "$T/hup.jsonl" 3
printf 'range = 12\nmin-points = 60000\ngain = 2\n' > "$T/hup.conf"
kill -HUP $SPID; n1=$(lines "$T/hup.jsonl")
waitlines "$T/hup.jsonl" $((n1 + 4))
printf 'range = 12\nmin-points = many\n' > "$T/hup.conf"
kill -HUP $SPID; n2=$(lines "$T/hup.jsonl")
waitlines "$T/hup.jsonl" $((n2 + 3))
kill -TERM $SPID; wait $SPID; rc=$?
kill $WDOG 2>/dev/null
endfeed
# A detection, not a track (tracks carry x_m too, and coast on after their objects stop being detected).
check "SIGHUP: detections before the reload" sh -c "sed -n '3,${n1}p' '$T/hup.jsonl' | grep -q '\"detections\":\\[{'"
check "SIGHUP: none from the second sweep after it (min-points 60000), the link kept" \
    sh -c "sed -n '$((n1 + 2)),\$p' '$T/hup.jsonl' | grep -q '\"detections\":\\[{' && exit 1; grep -q 'reconnects 0' '$T/hup.err' && test $rc -eq 0"
check "SIGHUP: a setting SIGHUP cannot change is named: gain applies after a restart" \
    grep -q "SIGHUP: gain changed: applies after a restart; the running value stays" "$T/hup.err"
check "SIGHUP: a bad file is named with its line; the running settings stay" \
    sh -c "grep -q \"hup.conf:2: --min-points: 'many' is not a whole number\" '$T/hup.err' && grep -q 'the running settings stay' '$T/hup.err' && test \$(sed -n '$((n2 + 2)),\$p' '$T/hup.jsonl' | wc -l) -ge 1"

# SIGTERM: motor_off, then exit 0.
feed "tcp:127.0.0.1:$((PORT + 6))" --pace device
timeout 30 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 6))" --range 2 --no-lcm --quiet & SPID=$!
sleep 1.5
kill -TERM $SPID; wait $SPID; rc=$?
sleep 0.2
endfeed
check "SIGTERM: sonard exits 0" test "$rc" -eq 0
check "SIGTERM: sonar-feed saw motor_off" grep -q "^motor_off" "$T/feed.log"

# The vehicle's pose over LCM (SONAR_POSE, sonar.pose_t), here from a log played at its own pace: a
# sonar 5 m north, 2 m west of the origin, heading east. Detections and tracks come out in the world.
# The log plays at 20 Hz while the fast-paced sonar ends in a fraction of a second: how many poses
# arrive first depends on the machine, so one or more is what is checked.
python3 tools/data/pose_log.py "$types" "$T/poses.lcm" --still 5 -2 90 --seconds 40 --hz 20
feed "tcp:127.0.0.1:$((PORT + 7))" --pace fast
timeout 60 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 7))" --range 12 --sweeps 4 --json --no-lcm \
    --pose-lcm "file://$T/poses.lcm?mode=r" > "$T/plcm.jsonl" 2> "$T/plcm.err"; rc=$?
endfeed
check "SONAR_POSE over LCM: exit 0, the poses counted, every sweep in the world frame at that pose" sh -c "test $rc -eq 0 &&
    grep -qE 'SONAR_POSE: [1-9][0-9]* poses, 0 did not decode, 0 refused' '$T/plcm.err' &&
    test \$(grep -c '\"frame\":\"world\",\"pose\":{\"north_m\":5.000,\"east_m\":-2.000,\"yaw_deg\":90.00}' '$T/plcm.jsonl') -eq 4"
check "SONAR_POSE: each detection's north, east is its sonar-frame x, y turned to face east and moved to (5, -2)" python3 -c "
import json
n = 0
for l in open('$T/plcm.jsonl'):
    for d in json.loads(l)['detections']:
        assert abs(d['north_m'] - (5 - d['y_m'])) < 0.01 and abs(d['east_m'] - (-2 + d['x_m'])) < 0.01, d
        n += 1
assert n > 0"

# SONAR_OBSTACLES: the obstacle map on LCM by default (a replay's, into a log), none with --obstacles off.
for o in on off; do
    "$B/sonard" --replay "$T/pool5.csv" --quiet --log-level warn --obstacles $o --lcm "file://$T/obs-$o.lcm?mode=w"
done
check "SONAR_OBSTACLES: the map after a beam, at most every 100 ms of beam time, by default; none with --obstacles off" python3 -c "
import importlib.machinery, sys
sys.path.insert(0, '$types')
from sonar import obstacles_t
m = importlib.machinery.SourceFileLoader('l', 'tools/data/lcm2mcap').load_module()
def obs(f):
    return [obstacles_t.decode(d) for ut, ch, d in m.read_events(open(f, 'rb')) if ch == 'SONAR_OBSTACLES']
on, off = obs('$T/obs-on.lcm'), obs('$T/obs-off.lcm')
gaps = [b.utime - a.utime for a, b in zip(on, on[1:])]
assert len(on) > 10 and not off and min(gaps) >= 100000 and all(o.count == 72 for o in on), (len(on), len(off), min(gaps))"

# A paused machine: sonard and the sonar stand-in frozen together (SIGSTOP, as a VM's pause freezes every process),
# 200 ms at a time, 8 times while requests are awaited at device pace. sonard must see each stall and wait it out:
# no request declared timed out (the stand-in answers as soon as it runs again).
feed "tcp:127.0.0.1:$((PORT + 40))" --pace device
"$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 40))" --range 12 --step 4 --no-lcm --quiet > /dev/null 2> "$T/stall.err" & sp=$!
sleep 1
for i in 1 2 3 4 5 6 7 8; do
    kill -STOP $sp $FEEDPID; sleep 0.2; kill -CONT $FEEDPID $sp; sleep 0.6
done
kill -TERM $sp; wait $sp; rc=$?
endfeed
grep 'loop: host stalls\|timeouts' "$T/stall.err" | sed 's/^/    /'
check "a paused machine (8 freezes of 200 ms, sonard and the sonar together): each stall seen, no request timed out" sh -c "
    test $rc -eq 0 && grep -q ' timeouts 0 ' '$T/stall.err' &&
    n=\$(sed -n 's/.*loop: host stalls \\([0-9]*\\), longest \\([0-9]*\\) ms.*/\\1 \\2/p' '$T/stall.err') &&
    set -- \$n && test \"\$1\" -ge 8 && test \"\$2\" -ge 150"

echo "live: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
