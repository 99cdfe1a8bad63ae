#!/bin/sh
# scan.sh -- the scan planner live (issue 26): sonar-feed at device pace on the wall clock (the moving scene) -> sonard
# --scan sweep and --scan follow side by side over TCP on 127.0.0.1, scored by tools/eval/score_live.py; follow mode
# under auto_transmit (says it cannot steer, sweeps); --scan follow without a live sonar refused. Bounded in time.
# Usage: sh tests/scan.sh BUILD_DIR [SECONDS]. Ends with "N passed, N failed".
set -u
B=${1:-build}
SEC=${2:-80}
T=$(mktemp -d /tmp/sonard-scan.XXXXXX)
PORT=$(( 20000 + ($$ % 20000) ))
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
# Both modes at once, on their own ports: the same scene, the same seed, the same wall clock.
sh tools/eval/live_scan.sh "$B" "$T" moving sweep "$SEC" "$PORT" > "$T/sweep.out" 2>&1 &
p1=$!
sh tools/eval/live_scan.sh "$B" "$T" moving follow "$SEC" $((PORT + 1)) > "$T/follow.out" 2>&1 &
p2=$!
wait $p1 $p2
cat "$T/sweep.out" "$T/follow.out"
get() { python3 -c "import json,sys; v = json.load(open(sys.argv[1]))[sys.argv[2]]; print(round(v, 3) if isinstance(v, float) else v)" "$T/moving-$1.score.json" "$2"; }
# The bound follow mode keeps: twice a plain sweep of the model (100 beams of 19.4 ms + 2R/c at 15 m + 6 ms a gradian x 4).
bound=12.68
check "follow: every angle revisited within twice a plain sweep ($bound s; got $(get follow unvisited_max_s) s)" \
    awk -v u="$(get follow unvisited_max_s)" -v b="$bound" 'BEGIN { exit !(u <= b) }'
check "follow: targets looked at sooner than a sweep does (median $(get follow revisit_median_s) s vs $(get sweep revisit_median_s) s)" \
    awk -v f="$(get follow revisit_median_s)" -v s="$(get sweep revisit_median_s)" 'BEGIN { exit !(f < s) }'
check "follow: the head skips what needs no ping ($(get follow beams) beams vs the sweep's $(get sweep beams))" \
    awk -v f="$(get follow beams)" -v s="$(get sweep beams)" 'BEGIN { exit !(f < s) }'
check "follow: tracking keeps working (MOTA $(get follow mota) >= 0.3)" \
    awk -v m="$(get follow mota)" 'BEGIN { exit !(m >= 0.3) }'
check "follow: no request timed out for the head's longer moves" grep -q "timeouts 0 " "$T/moving-follow.err"
# auto_transmit: the device steps itself; the planner says so and the sonar sweeps.
"$B/sonar-feed" --listen "tcp:127.0.0.1:$((PORT + 2))" --scene pool --pace fast --max-seconds 30 2> "$T/auto-feed.err" &
fp=$!
sleep 0.3
timeout 30 "$B/sonard" --sonar "tcp:127.0.0.1:$((PORT + 2))" --range 12 --mode auto --step 4 --scan follow --sweeps 1 \
    --no-lcm > /dev/null 2> "$T/auto.err"
kill $fp 2>/dev/null; wait $fp 2>/dev/null
check "follow under auto_transmit: said it cannot steer, and swept" grep -q "planner cannot steer it; sweeping" "$T/auto.err"
check "--scan follow without a live sonar is refused by name" \
    sh -c "'$B/sonard' --replay /dev/null --scan follow 2>&1 | grep -q 'scan follow steers a live sonar'"
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
