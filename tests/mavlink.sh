#!/bin/sh
# mavlink.sh -- sonard --mavlink against pymavlink (tests/mavlink_check.py) and sonar-feed's autopilot, live over
# loopback UDP: HEARTBEAT, OBSTACLE_DISTANCE (rate, fields, sectors against the simulated walls),
# OBSTACLE_DISTANCE_3D, the pose from ATTITUDE and LOCAL_POSITION_NED, foreign and broken traffic, an
# endpoint nobody listens on. Usage: sh tests/mavlink.sh BUILD_DIR. Ends with "N passed, N failed".
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-mavlink.XXXXXX)
PORT=$(( 24000 + ($$ % 15000) ))
PY=.venv-mavlink/bin/python
FEEDPID=""
trap '[ -n "$FEEDPID" ] && kill $FEEDPID 2>/dev/null; rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"

# 1. A sonar standing still in the pool, heading north; the checker is its autopilot and decodes all.
"$B/sonar-sim" --scene pool --out "$T/pool.csv" --truth "$T/pool.json"
"$B/sonar-feed" --listen "tcp:127.0.0.1:$PORT" --scene pool --max-seconds 90 2> "$T/feed.err" & FEEDPID=$!
sleep 0.3
timeout 90 "$B/sonard" --sonar "tcp:127.0.0.1:$PORT" --range 12 --step 2 --sweeps 3 --json --no-lcm \
    --mavlink "udpin:127.0.0.1:$((PORT + 1))" --mavlink-autopilot 1 > "$T/pool.jsonl" 2> "$T/pool.err" & SONARD=$!
$PY tests/mavlink_check.py --port $((PORT + 1)) --seconds 32 --truth "$T/pool.json" --out "$T/pool.rep" > "$T/chk.out" 2>&1
wait $SONARD; rc=$?
kill $FEEDPID 2>/dev/null; wait $FEEDPID 2>/dev/null; FEEDPID=""
cat "$T/chk.out"
grep '^sonard: mavlink\|^sonard: loop' "$T/pool.err"
check "pool: sonard exits 0 after its 3 sweeps" test $rc -eq 0
check "every message decodes with pymavlink, CRC and all (none bad), OBSTACLE_DISTANCE and HEARTBEAT among them" $PY -c "
import json; r = json.load(open('$T/pool.rep'))
assert r['bad_data'] == 0 and r['counts'].get('OBSTACLE_DISTANCE', 0) > 100 and r['counts'].get('HEARTBEAT', 0) > 10, r['counts']"
check "HEARTBEAT at 1 Hz as a peripheral: system 1, component 158, MAV_TYPE_ONBOARD_CONTROLLER, no autopilot" $PY -c "
import json; r = json.load(open('$T/pool.rep'))
assert abs(r['hb_rate_hz'] - 1.0) < 0.1, r['hb_rate_hz']
assert all(h['sysid'] == 1 and h['compid'] == 158 and h['type'] == 18 and h['autopilot'] == 8 for h in r['hb'])"
# ArduPilot's margin: AP_Proximity_MAV marks the sensor NoData when no message came for PROXIMITY_MAV_TIMEOUT_MS, 500 ms
# (libraries/AP_Proximity/AP_Proximity_MAV.cpp). Gaps are timed by the kernel's arrival stamps; the checker's own
# lateness (the machine paused or busy) is measured and taken out, and said: only sonard's own lateness can fail.
check "OBSTACLE_DISTANCE at 10 Hz (the default), never 0.5 s apart by sonard's own doing (ArduPilot's PROXIMITY_MAV_TIMEOUT_MS); no 3-D ones (off by default)" $PY -c "
import json; r = json.load(open('$T/pool.rep'))
print('  %.2f Hz (%.2f Hz outside the stalls), longest gap %.3f s, %.3f s of it sonard\'s own; the machine stalled %d times, %.2f s in all' %
      (r['od_rate_hz'], r['od_rate_unstalled_hz'], r['od_max_gap_s'], r['od_max_gap_own_s'], len(r['stalls']), r['stalled_s']))
assert r['od_rate_unstalled_hz'] >= 9.5 and r['od_max_gap_own_s'] <= 0.5, (r['od_rate_unstalled_hz'], r['od_max_gap_own_s'])
assert 'OBSTACLE_DISTANCE_3D' not in r['counts'], r['counts']"
sed 's/^/    /' "$T/out"
check "OBSTACLE_DISTANCE fields: 72 x 5 degrees from -20 (ArduPilot's faces nine entries each), body FRD, cm from --min-range to the range; never a 0" $PY -c "
import json; r = json.load(open('$T/pool.rep'))
f = [json.loads(x) for x in r['od_fields']]
assert len(f) == 1, f
f = f[0]
assert (f['increment'], f['increment_f'], f['angle_offset'], f['frame'], f['sensor_type'], f['min']) == (5, 5.0, -20.0, 12, 1, 50), f
assert r['zero_distances'] == 0, r['zero_distances']
assert 1190 <= f['max'] <= 1200 and f['sysid'] == 1 and f['compid'] == 158, f"
$PY -c "
import json, statistics; r = json.load(open('$T/pool.rep'))
e = [s['err'] for s in r['sectors'] if s['err'] is not None]
print('  sectors against the pool: %d with an echo, %d within 0.1 m, median %+.3f m, worst %+.2f m' % (len(e), sum(abs(x) <= 0.1 for x in e), statistics.median(e), max(e, key=abs)))"
check "sectors: the walls (and the posts) at >= 85 % of the echoing sectors within 0.1 m of the nearest in the sector; no wall missed" $PY -c "
import json; r = json.load(open('$T/pool.rep'))
s = r['sectors']
e = [x['err'] for x in s if x['err'] is not None]
assert len(e) >= 55 and sum(abs(x) <= 0.1 for x in e) >= 0.85 * len(e), e
assert not [x for x in s if x['got'] is None and x['want'] is not None], [x for x in s if x['got'] is None and x['want'] is not None]"
$PY -c "
import json; r = json.load(open('$T/pool.rep'))
print('  ArduPilot model, faces after the last message (got / nearest surface, m): ' +
      ', '.join('%d: %s / %s' % (f['face'], 'none' if f['got'] is None else '%.2f' % f['got'],
                                 'none' if f['want'] is None else '%.2f' % f['want']) for f in r['faces']))"
check "through a model of ArduPilot's proximity backend: every face's distance within 0.1 m of the nearest surface in it" $PY -c "
import json; r = json.load(open('$T/pool.rep'))
for f in r['faces']:
    assert (f['want'] is None) == (f['got'] is None) and (f['err'] is None or abs(f['err']) <= 0.1), f"
check "foreign traffic counted and ignored: broken CRCs, another dialect, another system's ATTITUDE and HEARTBEAT, a ground station, an unasked ACK" sh -c "
    grep -qE 'mavlink .*attitudes, .*[1-9][0-9]* bad CRC, [1-9][0-9]* foreign, [1-9][0-9]* from others\); autopilot system 1, .* [1-9][0-9]* other acks, [1-9][0-9]* other heartbeats' '$T/pool.err'"
check "the pose over MAVLink: every sweep tracked in the world frame, heading north at (0, 0)" sh -c "
    test \$(grep -c '\"frame\":\"world\",\"pose\":{\"north_m\":0.000,\"east_m\":0.000,\"yaw_deg\":0.00}' '$T/pool.jsonl') -eq 3"
# sonard's latency less its longest stall (its loop's own measure: time it was kept from running).
check "echo to message: at most 150 ms beyond sonard's longest stall (one 100 ms period of the 10 Hz OBSTACLE_DISTANCE, and the loop's wake)" sh -c "
    m=\$(sed -n 's/.*echo to message mean [0-9.]* ms, max \\([0-9.]*\\) ms.*/\\1/p' '$T/pool.err')
    l=\$(sed -n 's/^sonard: loop: host stalls [0-9]*, longest \\([0-9]*\\) ms.*/\\1/p' '$T/pool.err')
    echo \"max \$m ms, longest stall \${l:-?} ms\"; awk -v m=\"\$m\" -v l=\"\$l\" 'BEGIN { exit !(m != \"\" && l != \"\" && m - l <= 150) }'"
sed "s/^/    /" "$T/out"

# 2. A moving, turning vehicle: sonar-feed is its autopilot (ATTITUDE, LOCAL_POSITION_NED at 1 Hz until asked) and
#    its sonar; the checker is the router between them (it keeps the vehicle's poses) and a ground station that
#    listens for the tracks' OBSTACLE_DISTANCE_3D.
"$B/sonar-sim" --scene vehicle --out "$T/veh.csv" --truth "$T/veh.json" --sweeps 10
"$B/sonar-feed" --listen "tcp:127.0.0.1:$((PORT + 2))" --scene vehicle --mavlink "udpout:127.0.0.1:$((PORT + 11))" \
    --max-seconds 90 2> "$T/vfeed.err" & FEEDPID=$!
sleep 0.3
timeout 90 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 2))" --range 15 --samples 600 --step 4 --sweeps 10 --json --no-lcm \
    --min-points 8 --mavlink "udpin:127.0.0.1:$((PORT + 3))" --mavlink-3d on > "$T/veh.jsonl" 2> "$T/veh.err" & SONARD=$!
# The router (the checker) must outlast sonard's 10 sweeps (63 s at the device's pace, more on a loaded machine): once
# it stops, no pose reaches sonard, and its last sweeps fall back to the body frame. 80 s, not 66: CI once took longer.
$PY tests/mavlink_check.py --port $((PORT + 3)) --seconds 80 --listen-only --router $((PORT + 11)) --truth "$T/veh.json" \
    --out "$T/veh.rep" > "$T/vchk.out" 2>&1
wait $SONARD; rc=$?
kill $FEEDPID 2>/dev/null; wait $FEEDPID 2>/dev/null; FEEDPID=""
cat "$T/vchk.out"
grep '^sonard: mavlink' "$T/veh.err"
grep '^sonar_feed: mavlink' "$T/vfeed.err"
python3 tools/eval/score.py "$T/veh.json" "$T/veh.jsonl" --frame world --label "  live vehicle, world frame: " | tail -1
check "vehicle: exit 0, 10 sweeps, every one after the first (the autopilot heard, its pose asked for) in the world frame" sh -c "test $rc -eq 0 &&
    test \$(wc -l < '$T/veh.jsonl') -eq 10 && test \$(tail -n 9 '$T/veh.jsonl' | grep -c '\"frame\":\"world\"') -eq 9 &&
    grep -qE 'in [0-9]+ messages \([0-9]{3,} attitudes, [0-9]{3,} positions, 0 poses refused' '$T/veh.err'"
check "the pose asked for: the stand-in starts at 1 Hz, sonard's SET_MESSAGE_INTERVAL (both streams) takes it to 10 Hz, accepted" sh -c "
    grep -qE 'pose (9|10)\.[0-9] Hz, 2 interval requests \(2 accepted, 0 refused\)' '$T/veh.err' &&
    grep -qE 'intervals set, 0 refused' '$T/vfeed.err' && grep -qE ' 2 intervals set' '$T/vfeed.err'"
# Live, the beams' times follow a loaded machine's clock, not the simulator's schedule: the diver is
# where the truth says only roughly (recall 0.67 to 0.92 over runs), and a still object can be missed
# for a look. What stands still is where it is: two sightings of them, in any sweeps, must be there.
# Ten sweeps (63 s), not seven: precision over ~25 detections, not ~12, so one speckled wall residue
# more or less does not decide the check.
# The first sweep runs while the autopilot is found (its HEARTBEAT comes once a second) and its 1 Hz pose raised:
# part of it is in the body frame, so the world-frame precision is taken over the sweeps after it. Over nine runs
# here (four at bca0cf5, five after issue 36) it was 0.76 to 0.91, median 0.85: at 0.8 the check failed one run in
# three on timing alone. 0.7 still fails a change that doubles the false alarms (about 0.6).
tail -n +2 "$T/veh.jsonl" > "$T/veh1.jsonl"
check "vehicle, live: world-frame detection precision >= 0.7 after the first sweep; a still object found where it stands (0.5 m)" sh -c "
    python3 tools/eval/score.py '$T/veh.json' '$T/veh1.jsonl' --frame world --min-precision 0.7 && python3 -c \"
import json, math
still = {'post_a': (4.0, 5.0), 'post_b': (-5.0, -6.0), 'buoy': (0.5, 5.5)}
seen = {k: 0 for k in still}
for l in open('$T/veh1.jsonl'):
    for d in json.loads(l)['detections']:
        for k, (n, e) in still.items():
            if math.hypot(d['north_m'] - n, d['east_m'] - e) < 0.5:
                seen[k] += 1
assert sum(seen.values()) >= 2, seen  # one look each may be missed live\""
$PY -c "
import json, statistics; r = json.load(open('$T/veh.rep'))['moving_faces']; e = r['errors']
print('  moving vehicle through the ArduPilot model, once a second from 15 s: %d faces in %d snapshots, %d within 0.1 m, %d within 0.3 m, median %+.3f m, nearer than the obstacle %d, farther %d' % (
    len(e), r['snapshots'], sum(abs(x) <= 0.1 for x in e), sum(abs(x) <= 0.3 for x in e), statistics.median(e),
    sum(x < -0.1 for x in e), sum(x > 0.1 for x in e)))"
check "moving vehicle through the ArduPilot model: at least 30 faces scored, the median face within 0.1 m of the nearest obstacle" $PY -c "
import json, statistics; e = json.load(open('$T/veh.rep'))['moving_faces']['errors']
assert len(e) >= 30 and abs(statistics.median(e)) <= 0.1, (len(e), statistics.median(e))"
check "OBSTACLE_DISTANCE_3D: one burst a sweep with one time_boot_ms, IDs = the confirmed tracks', body FRD" $PY -c "
import json
r = json.load(open('$T/veh.rep'))
bursts = {}
for o in r['od3d']:
    assert o['frame'] == 12 and o['z'] == 0.0, o
    bursts.setdefault(o['time_boot_ms'], []).append(o['id'])
conf = [sorted(t['id'] for t in json.loads(l)['tracks'] if t['state'] == 'confirmed') for l in open('$T/veh.jsonl')]
conf = [c for c in conf if c]
got = [sorted(b) for _, b in sorted(bursts.items())]
assert got and got == conf[:len(got)] and len(got) >= len(conf) - 1, (got, conf)"

# 3. ArduPilot's forward face: a near post 10 degrees to starboard (3 m), a far one 10 degrees to port (6 m); then
#    the sonar is unplugged (sonar-feed killed) and sonard must fall silent so the autopilot marks it NoData.
"$B/sonar-sim" --scene faces --out "$T/faces.csv" --truth "$T/faces.json"
"$B/sonar-feed" --listen "tcp:127.0.0.1:$((PORT + 7))" --scene faces --max-seconds 60 2> /dev/null & FEEDPID=$!
sleep 0.3
timeout 30 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 7))" --range 8 --step 4 --json --no-lcm \
    --mavlink "udpin:127.0.0.1:$((PORT + 8))" --ignore-deg 80:100 --ignore-sector 355:2 > "$T/faces.jsonl" 2> "$T/faces.err" & SONARD=$!
$PY tests/mavlink_check.py --port $((PORT + 8)) --seconds 18 --truth "$T/faces.json" --out "$T/faces.rep" > "$T/fchk.out" 2>&1 &
CHK=$!
sleep 13
python3 -c 'import time; print(repr(time.time()))' > "$T/unplug"
kill $FEEDPID 2>/dev/null; wait $FEEDPID 2>/dev/null; FEEDPID=""
wait $CHK
kill $SONARD 2>/dev/null; wait $SONARD 2>/dev/null
grep '^sonard: mavlink' "$T/faces.err"
check "the forward face holds the near post (3 m, at 10 degrees), not the far one at 350 degrees that a second run would put there" $PY -c "
import json; r = json.load(open('$T/faces.rep'))
f = r['faces'][0]
print('  forward face: %s m, nearest surface %.2f m' % (f['got'], f['want']))
assert f['got'] is not None and abs(f['err']) <= 0.1, f"
check "--ignore-deg 80:100 and the old name --ignore-sector 355:2 (across forward): those sectors unknown (65535), the others scanned" $PY -c "
import json; r = json.load(open('$T/faces.rep'))
d, off = r['od_last'], -20
masked = [j for j in range(72) if (80 <= (5 * j + off) % 360 <= 100) or ((5 * j + off) % 360 >= 355 or (5 * j + off) % 360 <= 2)]
assert len(masked) == 7 and all(d[j] == 65535 for j in masked), [(j, d[j]) for j in masked]
assert all(d[j] != 65535 for j in range(72) if j not in masked), d"
check "the old name --ignore-sector is said deprecated, with its new name" \
    grep -q "warning: ignore-sector is deprecated: it is now ignore-deg (taken as that)" "$T/faces.err"
check "unplugged: OBSTACLE_DISTANCE stops within 1 s, so the autopilot marks the sonar NoData within 1.5 s" sh -c "
    $PY -c \"
import json; r = json.load(open('$T/faces.rep')); t = float(open('$T/unplug').read())
print('  last OBSTACLE_DISTANCE %.2f s after the unplug: NoData %.2f s after it' % (r['od_last_abs'] - t, r['od_last_abs'] + 0.5 - t))
assert r['od_last_abs'] + 0.5 - t <= 1.5\" && grep -q 'OBSTACLE_DISTANCE withheld' '$T/faces.err'"

# 4. An autopilot that refuses SET_MESSAGE_INTERVAL: said once, counted, the pose used at the rate it comes.
"$B/sonar-feed" --listen "tcp:127.0.0.1:$((PORT + 9))" --scene vehicle --mavlink "udpout:127.0.0.1:$((PORT + 10))" \
    --mavlink-refuse --max-seconds 60 2> "$T/rfeed.err" & FEEDPID=$!
sleep 0.3
timeout 60 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 9))" --range 15 --samples 600 --step 10 --sweeps 2 --json --no-lcm \
    --mavlink "udpin:127.0.0.1:$((PORT + 10))" > "$T/refuse.jsonl" 2> "$T/refuse.err"; rc=$?
kill $FEEDPID 2>/dev/null; wait $FEEDPID 2>/dev/null; FEEDPID=""
grep '^sonard: mavlink' "$T/refuse.err"
check "a refused interval request: exit 0, said once, counted, the pose taken at the 1 Hz it comes" sh -c "test $rc -eq 0 &&
    test \$(grep -c 'refused SET_MESSAGE_INTERVAL' '$T/refuse.err') -eq 1 &&
    grep -qE 'pose (0\.[5-9]|1\.[0-4]) Hz, [2-9][0-9]* interval requests \(0 accepted, [2-9][0-9]* refused\)' '$T/refuse.err'"

# 5. An endpoint nobody answers never holds up the sonar.
"$B/sonar-feed" --listen "tcp:127.0.0.1:$((PORT + 4))" --scene pool --max-seconds 60 2> /dev/null & FEEDPID=$!
sleep 0.3
timeout 60 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 4))" --range 12 --step 10 --sweeps 2 --json --no-lcm \
    --mavlink "udpout:127.0.0.1:$((PORT + 5))" > "$T/deaf.jsonl" 2> "$T/deaf.err"; rc=$?
kill $FEEDPID 2>/dev/null; wait $FEEDPID 2>/dev/null; FEEDPID=""
grep '^sonard: mavlink' "$T/deaf.err"
check "an endpoint nobody listens on: the sweeps run as without it, messages counted as dropped" sh -c "
    test $rc -eq 0 && test \$(wc -l < '$T/deaf.jsonl') -eq 2 && grep -qE 'HEARTBEAT \([1-9][0-9]* dropped\)' '$T/deaf.err' &&
    grep -q 'status frames .* timeouts 0 ' '$T/deaf.err'"
"$B/sonard" --sonar "tcp:127.0.0.1:1" --mavlink "tcp:127.0.0.1:5760" > /dev/null 2> "$T/url.err"; rc=$?
check "a MAVLink URL of another form: exit 2, the forms named" sh -c "test $rc -eq 2 &&
    grep -q -- '--mavlink tcp:127.0.0.1:5760: udpin:ADDR:PORT, udpout:HOST:PORT or serial:PATH' '$T/url.err'"
"$B/sonard" --sonar "tcp:127.0.0.1:1" --mavlink "udpin:127.0.0.1:99999" > /dev/null 2> "$T/port.err"; rc=$?
check "a port out of range: exit 2 before anything runs, named" sh -c "test $rc -eq 2 &&
    grep -q -- '--mavlink udpin:127.0.0.1:99999: udpin:ADDR:PORT with a port 1..65535' '$T/port.err'"
"$B/sonard" --replay "$T/pool.csv" --mavlink "udpin:127.0.0.1:$((PORT + 6))" > /dev/null 2> "$T/rep.err"; rc=$?
check "--mavlink with --replay: exit 2, said why" sh -c "test $rc -eq 2 && grep -q -- '--mavlink URL goes with --sonar' '$T/rep.err'"

# 6. A reload (SIGHUP) turns the frame by 90 degrees and moves --min-range: OBSTACLE_DISTANCE takes both from the
# pipeline beam by beam, so from the sweep the new settings take over at, the map and the detections agree.
printf 'range = 12\nstep = 2\nangle-offset = 0\nmin-range = 0.5\n' > "$T/hup.conf"
"$B/sonar-feed" --listen "tcp:127.0.0.1:$((PORT + 12))" --scene pool --pace x4 --max-seconds 120 2> /dev/null & FEEDPID=$!
$PY tests/mavlink_check.py --port $((PORT + 13)) --seconds 90 --listen-only --out "$T/hup.rep" --od-log "$T/hup.od" > /dev/null 2>&1 & CHK=$!
sleep 0.3
# Not under timeout(1), which forwards only the first SIGHUP; a watchdog bounds it instead.
"$B/sonard" --config "$T/hup.conf" --sonar "tcp:127.0.0.1:$((PORT + 12))" --json --no-lcm --log-level warn \
    --mavlink "udpin:127.0.0.1:$((PORT + 13))" > "$T/hup.jsonl" 2> "$T/hup.err" & SONARD=$!
( sleep 100; kill -KILL $SONARD ) > /dev/null 2>&1 & WDOG=$! # its sleep, orphaned by the kill below, must not hold a pipe
lines() { wc -l < "$1" 2>/dev/null || echo 0; }
waitlines() { i=0; while [ "$(lines "$1")" -lt "$2" ] && [ $i -lt 1200 ]; do sleep 0.05; i=$((i + 1)); done; }
waitlines "$T/hup.jsonl" 5
printf 'range = 12\nstep = 2\nangle-offset = 100\nmin-range = 2\n' > "$T/hup.conf"
kill -HUP $SONARD; n1=$(lines "$T/hup.jsonl")
waitlines "$T/hup.jsonl" $((n1 + 4))
kill -TERM $SONARD; wait $SONARD; rc=$?
kill $WDOG $CHK $FEEDPID 2>/dev/null; wait $CHK $FEEDPID 2>/dev/null; FEEDPID=""
check "SIGHUP: sonard keeps running through the reload and exits 0 on SIGTERM, nothing said amiss" \
    sh -c "test $rc -eq 0 && ! grep -q . '$T/hup.err'"
check "SIGHUP: OBSTACLE_DISTANCE and the detections turn together by angle-offset 100 gradians; min_distance 50 -> 200 cm" \
    $PY tests/mavlink_reload_check.py "$T/hup.jsonl" "$T/hup.od" $n1
sed 's/^/    /' "$T/out"

echo "mavlink: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
