#!/bin/sh
# deb.sh -- the Debian package on this machine (CI's own root): dpkg -i, sonard and its tools from the installed paths,
# the sonard user, the installed Python types and jar, the units' exposure (systemd-analyze security --offline), two
# sonard@ instances on one LCM bus (udpm inside a network namespace of their own) against two sonar-feeds, then
# dpkg -r and dpkg -P, checking nothing is left. Usage: sh tests/deb.sh BUILD_DIR. Ends with "N passed, N failed".
set -u
B=${1:-build}
V=$("$B/sonard" --version | awk '{print $2}')
DEB="$B/sonard_${V}_$(dpkg --print-architecture).deb"
if [ "$(id -u)" -ne 0 ]; then
    echo "deb: SKIPPED: installing a package needs root (CI runs as root); build it with make deb"
    echo "deb: 0 passed, 0 failed, 1 skipped"
    exit 0
fi
if dpkg-query -W -f='${Status}' sonard 2> /dev/null | grep -q 'ok installed'; then
    echo "deb: SKIPPED: a sonard package is already installed here; this test does not replace or remove it"
    echo "deb: 0 passed, 0 failed, 1 skipped"
    exit 0
fi
T=$(mktemp -d /tmp/sonard-deb.XXXXXX)
PORT=$(( 22000 + ($$ % 15000) ))
trap 'dpkg -P sonard > /dev/null 2>&1; rm -f /etc/sonard/t1.conf /etc/sonard/t2.conf; rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"

dpkg -i "$DEB" > "$T/install.log" 2>&1
rc=$?
check "dpkg -i $(basename "$DEB") (exit 0)" sh -c "test $rc -eq 0 || { cat '$T/install.log'; exit 1; }"
check "the installed sonard is on the PATH at /usr/bin and says its version ($V)" sh -c "
test \"\$(command -v sonard)\" = /usr/bin/sonard && test \"\$(/usr/bin/sonard --version)\" = 'sonard $V'"
check "the sonard system user exists, in dialout, and owns /var/lib/sonard" sh -c "
uid=\$(id -u sonard) && test \"\$uid\" -lt 1000 && id -nG sonard | tr ' ' '\n' | grep -qx dialout &&
test \"\$(stat -c %U /var/lib/sonard)\" = sonard"
check "the example config is a conffile at /etc/sonard/sonard.conf, and sonard reads it" sh -c "
dpkg-query -W -f='\${Conffiles}' sonard | grep -q /etc/sonard/sonard.conf &&
/usr/bin/sonard --config /etc/sonard/sonard.conf --help > /dev/null"
/usr/bin/sonar-sim --scene pool --out "$T/pool.csv" --truth "$T/pool.json" > /dev/null 2>&1
/usr/bin/sonard --replay "$T/pool.csv" --json --no-lcm > "$T/pool.jsonl" 2> "$T/pool.err"
check "--replay from the installed paths: the pool's objects found (F1 >= 0.95)" \
    python3 tools/eval/score.py "$T/pool.json" "$T/pool.jsonl" --min-f1 0.95
check "the installed Python LCM types import with the system Python and decode what sonard encodes" sh -c "
cd / && /usr/bin/python3 -c 'from sonar import beam_t, detections_t, status_t, tracks_t; m = beam_t(); m.samples = b\"\"; beam_t.decode(m.encode())'"
check "the jar for lcm-spy holds the sonar types" python3 -c "
import zipfile; n = zipfile.ZipFile('/usr/share/java/sonard.jar').namelist()
assert all('sonar/%s.class' % t in n for t in ('beam_t', 'detections_t', 'status_t', 'tracks_t')), n"
check "the docs, the manual pages, the LCM type sources and the units are where the package says" sh -c "
test -f /usr/share/doc/sonard/README.md && test -f /usr/share/doc/sonard/configuration.md &&
test -f /usr/share/sonard/lcm_types/sonar_beam_t.lcm && test -f /lib/systemd/system/sonard.service &&
test -f /lib/systemd/system/sonard@.service && test -f /lib/systemd/system/sonar-view.service &&
zcat /usr/share/man/man1/sonard.1.gz | grep -q -- --discover && zcat /usr/share/man/man1/sonar-view.1.gz | grep -q -- --listen"
check "sonar-ros2 without ROS 2: one line saying how to get it, exit 2; its manual page" sh -c "
cd / && /usr/bin/sonar-ros2 2> '$T/ros2.err'; test \$? -eq 2 && test \$(wc -l < '$T/ros2.err') -eq 1 &&
grep -q 'source your ROS 2' '$T/ros2.err' && zcat /usr/share/man/man1/sonar-ros2.1.gz | grep -q -- --prefix"
if [ -x .venv-ros2/bin/python ] && unshare -n true 2> /dev/null; then
    # The installed bridge on an rclpy found on PATH (as a sourced distribution's is), with the installed LCM types;
    # in a network namespace, as its bus and DDS must not leave the machine.
    check "sonar-ros2 with an rclpy on PATH: the installed bridge starts on the installed types and stops at --max-seconds" \
        unshare -n sh -c "ip link set lo up && ip route add 224.0.0.0/4 dev lo &&
        PATH='$PWD/.venv-ros2/bin':\$PATH timeout 60 /usr/bin/sonar-ros2 --lcm 'udpm://239.255.76.67:7667?ttl=0' --max-seconds 2 \
            2> '$T/ros2run.err' && grep -q 'in frame sonar_link' '$T/ros2run.err'"
else
    echo "deb: sonar-ros2 not run with ROS 2: no .venv-ros2 (make ros2) or no network namespace"
fi

# The site survey as sonard.service's header says to record it: as the sonard user, with the shipped config (its
# survey = /var/lib/sonard/site.survey), from a Ping360 serving the empty site; then loaded by that config at start.
/usr/bin/sonar-feed --listen tcp:127.0.0.1:$((PORT + 2)) --scene pool --empty --pace fast --max-seconds 60 2> /dev/null & F=$!
sleep 0.3
timeout 60 runuser -u sonard -- /usr/bin/sonard --config /etc/sonard/sonard.conf --sonar tcp:127.0.0.1:$((PORT + 2)) \
    --no-lcm --quiet --survey 10 2> "$T/survey.err"
src=$?
kill $F 2> /dev/null; wait $F 2> /dev/null
check "the survey recorded as the unit's header says: /var/lib/sonard/site.survey written, the sonard user's" sh -c "
test $src -eq 0 && grep -q 'survey: written to /var/lib/sonard/site.survey' '$T/survey.err' &&
test \"\$(stat -c %U /var/lib/sonard/site.survey)\" = sonard || { cat '$T/survey.err'; exit 1; }"
/usr/bin/sonar-feed --listen tcp:127.0.0.1:$((PORT + 2)) --scene pool --pace fast --max-seconds 60 2> /dev/null & F=$!
sleep 0.3
timeout 60 runuser -u sonard -- /usr/bin/sonard --config /etc/sonard/sonard.conf --sonar tcp:127.0.0.1:$((PORT + 2)) \
    --no-lcm --quiet --sweeps 3 2> "$T/survey_use.err"
kill $F 2> /dev/null; wait $F 2> /dev/null
check "... and the shipped config loads it at start, with no flag" sh -c "
grep -q 'survey: of .* in use' '$T/survey_use.err' || { cat '$T/survey_use.err'; exit 1; }"

# The units: their exposure as systemd scores it, the serial device by the ACL and dialout only.
for u in sonard.service sonard@front.service sonar-view.service; do
    systemd-analyze security --offline=true --root=/ "$u" > "$T/sec.$u" 2>&1
    check "systemd-analyze security --offline: $u exposure <= 2.0 ($(grep -o 'exposure level for [^:]*: [0-9.]*' "$T/sec.$u" | awk '{print $NF}'))" \
        python3 -c "
import re, sys; t = open('$T/sec.$u').read(); m = re.search(r'Overall exposure level for \S+: ([0-9.]+)', t)
assert m and float(m.group(1)) <= 2.0, t[-600:]"
done
check "the units reach serial ports only through DeviceAllow (DevicePolicy=closed) and the dialout group" sh -c "
for u in /lib/systemd/system/sonard.service /lib/systemd/system/sonard@.service; do
  grep -qx 'DevicePolicy=closed' \$u && grep -qx 'DeviceAllow=char-ttyUSB rw' \$u && grep -qx 'SupplementaryGroups=dialout' \$u &&
  grep -qx 'User=sonard' \$u && grep -qx 'CapabilityBoundingSet=' \$u || exit 1
done"
systemd-analyze verify /lib/systemd/system/sonard.service /lib/systemd/system/sonard@front.service /lib/systemd/system/sonar-view.service > "$T/verify" 2>&1
check "systemd-analyze verify: no complaint about the units" sh -c "! grep -i 'sonar' '$T/verify' || { cat '$T/verify'; exit 1; }"

# Two instances of the template, run as their ExecStart says, on one LCM bus: t1 drives a full-turn sonar over UDP at
# 12 m, t2 a 100:200 sector over TCP at 8 m. Each stream must carry only its own sonar's beams under its own prefix.
# The feeders keep the device's pace: at --pace fast, on a loaded machine, lcm-logger's UDP buffer overflowed
# (187 of 200 t1 beams, 67 of 75 t2 beams, no t2 STATUS, beside three busy loops); at the device's pace it keeps up.
exec_of() { sed -n 's/^ExecStart=//p' /lib/systemd/system/sonard@.service | sed "s/%i/$1/g"; }
cat > /etc/sonard/t1.conf <<EOF
sonar = udp:127.0.0.1:$PORT
range = 12
step = 4
sweeps = 2
lcm = udpm://239.255.76.67:7667?ttl=0
EOF
cat > /etc/sonard/t2.conf <<EOF
sonar = tcp:127.0.0.1:$((PORT + 1))
range = 8
step = 4
sector = 100:200
sweeps = 3
lcm = udpm://239.255.76.67:7667?ttl=0
EOF
cat > "$T/two.sh" <<EOF
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 3
/usr/bin/sonar-feed --listen udp:127.0.0.1:$PORT --scene pool --max-seconds 60 2> "$T/f1.err" &
/usr/bin/sonar-feed --listen tcp:127.0.0.1:$((PORT + 1)) --scene open --max-seconds 60 2> "$T/f2.err" &
lcm-logger -f --lcm-url='udpm://239.255.76.67:7667?ttl=0' "$T/bus.lcm" > "$T/logger.out" 2>&1 & L=\$!
sleep 0.5
timeout 60 $(exec_of t1) > "$T/t1.out" 2> "$T/t1.err" & A=\$!
timeout 60 $(exec_of t2) > "$T/t2.out" 2> "$T/t2.err" & Z=\$!
$(sed -n 's/^ExecStart=//p' /lib/systemd/system/sonar-view.service) 2> "$T/view.err" & VW=\$!
sleep 2
python3 tests/blueos_view_check.py --url http://127.0.0.1:8360/ --vendor /usr/share/sonard/view/vendor > "$T/view.out" 2>&1
echo \$? > "$T/view.rc"
kill \$VW
wait \$A; ra=\$?
wait \$Z; rz=\$?
sleep 0.5
kill \$L
echo "\$ra \$rz" > "$T/rc"
EOF
echo "t1: $(exec_of t1)"
echo "t2: $(exec_of t2)"
if unshare -rn true 2> /dev/null; then
    unshare -rn sh "$T/two.sh"
    cat "$T/view.out"
    check "the installed view (sonar-view.service's ExecStart, its vendored websockets, no LCM binding) serves the page, /register_service and the WebSocket under BlueOS's prefix" \
        sh -c "test \"\$(cat '$T/view.rc')\" = 0 || { cat '$T/view.err'; exit 1; }"
    check "two sonard@ instances, both exit 0 after their sweeps" sh -c "test \"\$(cat '$T/rc')\" = '0 0' || { cat '$T/t1.err' '$T/t2.err'; exit 1; }"
    check "one LCM bus, two streams kept apart: t1_* only the UDP full-turn sonar at 12 m, t2_* only the TCP sector at 8 m" \
        /usr/bin/python3 - "$T/bus.lcm" <<'PY'
import sys
sys.path.insert(0, "tools/data")
from lcm_log import events
from sonar import beam_t, detections_t, status_t
seen = {}
for _, ch, data in events(sys.argv[1]):
    seen.setdefault(ch, []).append(data)
print({k: len(v) for k, v in sorted(seen.items())})
assert set(seen) >= {"t1_SONAR_BEAM", "t1_SONAR_DETECTIONS", "t1_SONAR_STATUS",
                     "t2_SONAR_BEAM", "t2_SONAR_DETECTIONS", "t2_SONAR_STATUS"}, sorted(seen)
assert all(c.startswith(("t1_", "t2_")) for c in seen if c != "LCM_SELF_TEST"), sorted(seen)  # LCM udpm self-test aside, nothing unprefixed
b1 = [beam_t.decode(d) for d in seen["t1_SONAR_BEAM"]]
b2 = [beam_t.decode(d) for d in seen["t2_SONAR_BEAM"]]
assert all(abs(b.range_m - 12) < 0.5 for b in b1) and all(abs(b.range_m - 8) < 0.5 for b in b2)
a1 = {b.angle for b in b1}
a2 = {b.angle for b in b2}
assert max(a1) - min(a1) > 300 and all(100 <= a <= 200 for a in a2), (min(a1), max(a1), min(a2), max(a2))
d1 = [detections_t.decode(d) for d in seen["t1_SONAR_DETECTIONS"]]
d2 = [detections_t.decode(d) for d in seen["t2_SONAR_DETECTIONS"]]
assert len(d1) == 2 and len(d2) == 3, (len(d1), len(d2))
print("t1: %d beams, angles %d..%d; t2: %d beams, angles %d..%d" % (len(b1), min(a1), max(a1), len(b2), min(a2), max(a2)))
PY
else
    ko "two sonard@ instances: unshare -rn (a network namespace for a private LCM bus) is not allowed here"
fi
rm -f /etc/sonard/t1.conf /etc/sonard/t2.conf

# Remove, then purge: nothing of the package left, the conffile only until the purge.
dpkg -r sonard > "$T/rm.log" 2>&1
check "dpkg -r: the binaries and units are gone, the edited-or-not conffile stays" sh -c "
! test -e /usr/bin/sonard && ! test -e /lib/systemd/system/sonard@.service && ! test -e /usr/lib/python3/dist-packages/sonar &&
test -f /etc/sonard/sonard.conf"
dpkg -P sonard > "$T/purge.log" 2>&1
check "dpkg -P: the config, the sonard user and /var/lib/sonard are gone; dpkg knows nothing of sonard" sh -c "
! test -e /etc/sonard && ! getent passwd sonard > /dev/null && ! getent group sonard > /dev/null && ! test -e /var/lib/sonard &&
! dpkg-query -W sonard > /dev/null 2>&1"

echo "deb: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
