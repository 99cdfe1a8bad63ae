#!/bin/sh
# view.sh -- the live view in a real headless browser (Debian's chromium, driven by selenium): sonar-feed plays make demo's
# pool as a device-paced Ping360, sonard drives it and publishes on a udpm bus inside a network namespace of its own,
# sonar_view.py serves the page; tests/view_check.py checks it. Usage: sh tests/view.sh BUILD_DIR. Ends with "N passed, N failed".
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-view.XXXXXX)
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
need_netns view "a network namespace for a private LCM bus"
URL='udpm://239.255.76.67:7667?ttl=0'
"$B/sonar-sim" --scene pool --out "$T/pool.csv" --truth "$T/pool.json" > /dev/null 2>&1
cat > "$T/run.sh" <<EOS
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 3
.venv-view/bin/python tests/lcm_udpm_check.py > "$T/udpm.out" 2>&1
"$B/sonar-feed" --listen tcp:127.0.0.1:5360 --scene pool --max-seconds 120 2> "$T/feed.err" & F=\$!
"$B/sonar-feed" --listen tcp:127.0.0.1:5361 --scene pool --pace fast --max-seconds 120 2> "$T/feed2.err" & F2=\$!
.venv-view/bin/python tools/view/sonar_view.py --lcm '$URL' --listen 127.0.0.1:8360 --types "$B/lcm/python" 2> "$T/view.err" & V=\$!
sleep 1
/usr/bin/python3 tests/view_check.py --url http://127.0.0.1:8360/ --truth "$T/pool.json" --shot "$B/view.png" --report "$T/report.json" \\
    --sonard "$B/sonard --sonar tcp:127.0.0.1:5360 --range 12 --step 4 --publish-filtered --lcm $URL --quiet" \\
    --sonard-fast "$B/sonard --sonar tcp:127.0.0.1:5361 --range 12 --lcm $URL --quiet" --health http://127.0.0.1:8360/health \\
    --bad-cmd ".venv-view/bin/python -c \"import lcm; l = lcm.LCM('$URL'); [l.publish(c, b'\\\\x00garbage') for c in ('SONAR_BEAM', 'SONAR_DETECTIONS', 'SONAR_STATUS')]\"" \\
    > "$T/check.out" 2>&1
echo \$? > "$T/rc"
kill \$V \$F \$F2 2> /dev/null
wait
EOS
unshare -rn sh "$T/run.sh"
cat "$T/udpm.out" "$T/check.out" > "$T/all.out"
cat "$T/all.out"
sed 's/^/    view: /' "$T/view.err" | head -10
pass=$(grep -c '^\[  PASS' "$T/all.out")
fail=$(grep -c '^\[  FAIL' "$T/all.out")
if [ "$(cat "$T/rc")" != 0 ] && [ "$fail" -eq 0 ]; then fail=1; fi
test -s "$B/view.png" && echo "view: screenshot in $B/view.png"
echo "view: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
