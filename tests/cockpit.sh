#!/bin/sh
# cockpit.sh -- sonard in Cockpit (tests/cockpit_check.py): a BlueOS stand-in, Cockpit's discovery, both widgets in Debian's
# headless chromium, the survey's actions against a simulated Ping360, on a udpm bus inside a network namespace of its own.
# Usage: sh tests/cockpit.sh BUILD_DIR. Ends with "cockpit: N passed, N failed"; screenshots in BUILD_DIR/cockpit*.png.
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-cockpit.XXXXXX)
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
need_netns cockpit "a network namespace for a private LCM bus"
cat > "$T/run.sh" <<EOS
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 3
/usr/bin/python3 tests/cockpit_check.py --build "$B" --tmp "$T" --lcm 'udpm://239.255.76.67:7667?ttl=0' \\
    --view-python .venv-view/bin/python --report "$T/report.json" --shot "$B/cockpit.png" > "$T/check.out" 2>&1
echo \$? > "$T/rc"
EOS
timeout 600 unshare -rn sh "$T/run.sh"
cat "$T/check.out"
sed 's/^/    sonard: /' "$T/sonard.err" 2> /dev/null | grep -i "control\|survey\|error" | head -20
sed 's/^/    view: /' "$T/view.err" 2> /dev/null | grep -v "^    view: sonar_view: http" | head -10
test -s "$T/report.json" && cp "$T/report.json" "$B/cockpit.json"
tally cockpit "$T/check.out" "$T/rc"
