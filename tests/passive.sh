#!/bin/sh
# passive.sh -- `make passive-test`: sonard --passive beside a program that drives the head, in a network namespace of
# its own. sonar-feed plays the demo's pool; tools/sim/passive/bridge.py relays it like BlueOS's bridges (every byte
# to every client); tools/sim/passive/pv_driver.py steps the head as Ping Viewer does, or switches it to
# auto_transmit, and records every beam it receives. Each run: sonard's detections equal `sonard --replay` of the
# driver's recording, sonard sent the bridge nothing but device_information requests (counted by message id), and
# the pool's objects are found. Then a driver that changes gain and range, one that pauses (idle said within 2 s),
# a bridge that forgets silent clients, a Ping1D and garbage on the bridge, two drivers at once, and the options
# that command the head refused. Usage: sh tests/passive.sh BUILD_DIR. Ends with "N passed, N failed".
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-passive.XXXXXX)
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
need_netns passive "a network namespace of its own"
"$B/sonar-sim" --scene pool --sweeps 7 --out /dev/null --truth "$T/pool.json" > /dev/null 2>&1

# run NAME "FEED OPTIONS" "BRIDGE OPTIONS" "DRIVER OPTIONS" [SECOND DRIVER OPTIONS]: one passive run, its files in $T/NAME.*
run() {
    n=$1
    cat > "$T/$n.sh" <<EOF
ip link set lo up || exit 3
"$B/sonar-feed" --listen udp:127.0.0.1:5360 --scene pool $2 --max-seconds 90 2> "$T/$n.feed" & F=\$!
python3 tools/sim/passive/bridge.py --listen 127.0.0.1:9092 --sonar 127.0.0.1:5360 --seconds 90 --report "$T/$n.bridge" $3 & BR=\$!
sleep 0.5
"$B/sonard" --sonar udp:127.0.0.1:9092 --passive --json --no-lcm 2>&1 > "$T/$n.jsonl" | python3 -u -c "
import sys, time
for line in sys.stdin:
    print('%.3f %s' % (time.time(), line), end='')" > "$T/$n.err" & S=\$!
sleep 0.5
${5:+python3 tools/sim/passive/pv_driver.py --bridge 127.0.0.1:9092 --out "$T/$n.csv2" $5 2> "$T/$n.driver2" & D2=\$!}
python3 tools/sim/passive/pv_driver.py --bridge 127.0.0.1:9092 --out "$T/$n.csv" $4 2> "$T/$n.driver"
${5:+wait \$D2}
sleep 0.5
pkill -TERM -x sonard; wait \$S
kill \$F \$BR; wait
EOF
    # a pid namespace too: the pkill above reaches only this run's sonard
    unshare -rnpf --mount-proc sh "$T/$n.sh"
    "$B/sonard" --replay "$T/$n.csv" --json --quiet --log-level warn --sweep-gap 2 > "$T/$n.replay" 2> /dev/null
}

# f1 FILE: the F1 of a --json file against the pool's truth.
f1() { python3 tools/eval/score.py "$T/pool.json" "$1" | sed -n 's/.*F1 \([0-9.]*\).*/\1/p' | head -1; }

# sent_only_hellos NAME: the bridge saw sonard (the client that sent no transducer request) send only id 6.
sent_only_hellos() {
    python3 -c "
import json, sys
r = json.load(open('$T/$1.bridge'))['clients']
ours = [c for c in r.values() if not set(c['ids']) & {'2601', '2602', '2903', '2600'}]
drivers = [c for c in r.values() if set(c['ids']) & {'2601', '2602'}]
print('sonard sent', ours[0]['ids'] if ours else None, '; the driver', [d['ids'] for d in drivers])
assert len(ours) == 1 and set(ours[0]['ids']) == {'6'} and drivers, r"
}

for m in ${PASSIVE_RUNS:-"step1:--mode step --step 1" "step2:--mode step --step 2" "auto1:--mode auto --step 1" "auto2:--mode auto --step 2"}; do
    n=${m%%:*}; o=${m#*:}
    pace=fast; case $n in auto*) pace=x10 ;; esac
    run "$n" "--pace $pace" "" "--range 12 --sweeps 8 $o"
    head -n 7 "$T/$n.jsonl" > "$T/$n.scored" # the demo's 7 sweeps; the driver ran one more so that all 7 are whole
    check "$n: sonard --passive's detections equal sonard --replay of the beams the driver received: $(python3 tests/passive_check.py "$T/$n.replay" "$T/$n.jsonl")" \
        python3 tests/passive_check.py "$T/$n.replay" "$T/$n.jsonl"
    check "$n: sonard sent the bridge only device_information requests: $(sent_only_hellos $n 2>&1 | tail -1)" sent_only_hellos "$n"
    case $n in
    *1) check "$n: the pool's objects found" python3 tools/eval/score.py "$T/pool.json" "$T/$n.scored" --min-f1 0.95 ;;
    *2)
        # At 2-gradian steps the detector itself reports a short piece of wall at the range's edge as an object
        # (docs/results.md): passive must do as well as sonard driving the head at the same step.
        if [ ! -f "$T/active2.jsonl" ]; then
            printf '%s\n' "ip link set lo up || exit 3" \
                "\"$B/sonar-feed\" --listen udp:127.0.0.1:5360 --scene pool --pace fast --max-seconds 60 2> /dev/null & F=\$!" \
                "sleep 0.3" \
                "timeout 60 \"$B/sonard\" --sonar udp:127.0.0.1:5360 --range 12 --step 2 --sweeps 7 --json --no-lcm > \"$T/active2.jsonl\" 2> /dev/null" \
                "kill \$F" > "$T/active2.sh"
            unshare -rn sh "$T/active2.sh"
        fi
        fp=$(f1 "$T/$n.scored"); fa=$(f1 "$T/active2.jsonl")
        check "$n: the pool's objects found as well as sonard driving the head at the same step: F1 $fp (driving: $fa)" \
            python3 -c "assert $fp >= $fa - 0.01" ;;
    esac
done

# The driver changes gain, then range, mid-run: each change said and counted, the sweep cut, still equal to the replay.
run change "--pace fast" "" "--mode step --range 12 --sweeps 9 --schedule 3:gain=1,5:range=20"
check "a driver that changes gain then range: both said ($(grep -c 'changed its settings' "$T/change.err")), still equal to the replay: $(python3 tests/passive_check.py "$T/change.replay" "$T/change.jsonl")" \
    sh -c "test \"\$(grep -c 'changed its settings' '$T/change.err')\" = 2 && python3 tests/passive_check.py '$T/change.replay' '$T/change.jsonl'"

# The driver pauses 4 s (and a bridge that forgets clients silent for 2.5 s): idle said within 2 s, sonard asks again,
# beams again when the driver resumes, the pause cuts the sweep in both.
run pause "--pace fast" "--forget 2.5" "--mode step --range 12 --sweeps 6 --schedule 2:pause=4"
t_pause=$(sed -n 's/^pv_driver: paused at \([0-9.]*\).*/\1/p' "$T/pause.driver")
t_idle=$(sed -n 's/^\([0-9.]*\) sonard: warning: passive: no beam.*/\1/p' "$T/pause.err" | head -1)
check "a driver that pauses: sonard says so $(python3 -c "print('%.2f' % ($t_idle - $t_pause))" 2> /dev/null) s after its last request (<= 2 s), then beams again" \
    python3 -c "assert 0 < $t_idle - $t_pause <= 2.0; assert 'beams again' in open('$T/pause.err').read()"
check "the bridge forgot sonard while the driver was quiet; sonard's requests made it a client again, and the rest still equals the replay: $(python3 tests/passive_check.py "$T/pause.replay" "$T/pause.jsonl")" \
    sh -c "python3 -c \"import json; r = json.load(open('$T/pause.bridge')); assert r['forgotten'] >= 1, r\" &&
           python3 tests/passive_check.py '$T/pause.replay' '$T/pause.jsonl'"
check "the paused run: sonard still sent only device_information requests ($(python3 -c "import json; print([c['ids'] for c in json.load(open('$T/pause.bridge'))['clients'].values()])"))" sent_only_hellos pause

# Another device and garbage on the bridge: ignored and counted, the detections unchanged.
run shared "--pace fast --ping1d 0.05 --garbage 0.05" "" "--mode step --range 12 --sweeps 7"
fr=$(sed -n 's/.* foreign \([0-9]*\) .*/\1/p' "$T/shared.err"); sent=$(sed -n 's/.*ping1d frames \([0-9]*\).*/\1/p' "$T/shared.feed")
check "a Ping1D and garbage on the bridge: its $sent frames counted as foreign ($fr), the junk skipped by the parser, still equal to the replay" \
    sh -c "test -n '$fr' && test '$fr' -ge '$sent' && test '$sent' -gt 0 && python3 tests/passive_check.py '$T/shared.replay' '$T/shared.jsonl'"

# Two drivers at once (12 m and 20 m): every beam used, the changes of geometry counted, nothing crashes.
run two "--pace fast" "" "--mode step --range 12 --sweeps 3" "--mode step --range 20 --sweeps 3"
check "two drivers at once: sonard takes both's beams ($(sed -n 's/.* beams \([0-9]*\) sweeps.*/\1/p' "$T/two.err")), counts the geometry flipping, exits 0" \
    sh -c "b=\$(sed -n 's/.* beams \([0-9]*\) sweeps.*/\1/p' '$T/two.err'); test \"\$b\" -ge \$(( \$(wc -l < '$T/two.csv') )) && grep -q 'changed its settings' '$T/two.err'"

# Options that command the head are refused with --passive, each named.
for o in "--gain auto" "--scan follow" "--sector 100:300" "--range 20" "--transmit-duration 100" "--step 2"; do
    "$B/sonard" --sonar udp:127.0.0.1:9 --passive $o > "$T/opt.out" 2>&1; rc=$?
    pat="${o%% *}.*--passive"
    check "--passive $o: refused, named ($(head -1 "$T/opt.out"))" sh -c "test $rc -eq 2 && grep -q -- '$pat' '$T/opt.out'"
done
echo "passive: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
