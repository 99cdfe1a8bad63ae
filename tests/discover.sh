#!/bin/sh
# discover.sh -- sonard --discover on loopback: sonar-feed answers discovery as a Ping360 does; the firmware asked on
# its data port; the URL listed drives it; a sonar on a foreign subnet warned about; malformed replies named and
# ignored; nobody answering. Only 127.0.0.1 is sent to. Usage: sh tests/discover.sh BUILD_DIR. Ends with "N passed, N failed".
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-discover.XXXXXX)
PORT=$(( 21000 + ($$ % 15000) ))
FEEDPID=""
trap '[ -n "$FEEDPID" ] && kill $FEEDPID 2>/dev/null; rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"

# 1. One simulated Ping360: discovery on PORT, the Ping Protocol on PORT+1 (a real one: 30303 and 12345).
"$B/sonar-feed" --listen "udp:127.0.0.1:$((PORT + 1))" --scene pool --discovery "udp:127.0.0.1:$PORT" --firmware 3.3.7 \
    --mac 54-10-EC-12-34-56 --pace fast --max-seconds 60 2> "$T/feed.err" & FEEDPID=$!
sleep 0.3
"$B/sonard" --discover --discover-to "127.0.0.1:$PORT" --discover-data-port $((PORT + 1)) > "$T/d1.out" 2> "$T/d1.err"
rc=$?
cat "$T/d1.out" "$T/d1.err"
check "--discover exits 0 and lists the device: address, MAC, firmware 3.3.7 (asked on its data port), URL" sh -c "
test $rc -eq 0 && grep -q '^127.0.0.1 *54-10-EC-12-34-56 *3.3.7 *udp:127.0.0.1:$((PORT + 1))\$' '$T/d1.out'"
check "--discover: found within its 2 s, no subnet warning for a loopback device" python3 -c "
import re; e = open('$T/d1.err').read()
m = re.search(r'1 Ping360 found in 2.0 s, the first after ([0-9.]+) ms', e)
assert m and float(m.group(1)) < 2000, e
assert 'warning' not in e, e"
url=$(awk 'NR == 2 {print $4}' "$T/d1.out")
timeout 60 "$B/sonard" --sonar "$url" --range 12 --step 4 --sweeps 3 --no-lcm --json --quiet > "$T/live.jsonl" 2> "$T/live.err"
check "the URL it lists drives the sonar: 3 full turns of 100 beams from $url" sh -c "
test \$(grep -c '\"beams\":100,' '$T/live.jsonl') -eq 3"
kill $FEEDPID 2>/dev/null; wait $FEEDPID 2>/dev/null; FEEDPID=""

# 2. A sonar whose address is on no local subnet (the classic 192.168.2.2 on a laptop at 10.x): warned.
"$B/sonar-feed" --listen "udp:127.0.0.1:$((PORT + 1))" --scene pool --discovery "udp:127.0.0.1:$PORT" \
    --claim-ip 198.51.100.7 --max-seconds 30 2> "$T/feed2.err" & FEEDPID=$!
sleep 0.3
"$B/sonard" --discover --discover-to "127.0.0.1:$PORT" --discover-data-port $((PORT + 1)) --discover-seconds 1 \
    > "$T/d2.out" 2> "$T/d2.err"
cat "$T/d2.out" "$T/d2.err"
check "a sonar claiming 198.51.100.7 (no local subnet): listed, and warned about with the local interfaces" sh -c "
grep -q '^198.51.100.7 .*(it answered from 127.0.0.1)' '$T/d2.out' &&
grep -q 'warning: the sonar at 198.51.100.7 is on no local interface.s subnet (.*127.0.0.1/8' '$T/d2.err'"
kill $FEEDPID 2>/dev/null; wait $FEEDPID 2>/dev/null; FEEDPID=""

# 3. Malformed replies: each named with where it came from and why, and the good one still listed.
python3 - "$PORT" > "$T/bad.log" 2>&1 <<'PY' &
import socket, sys, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(("127.0.0.1", int(sys.argv[1])))
s.settimeout(10)
data, peer = s.recvfrom(100)
assert data == b"Discovery", data
for r in (b"BR\x00\x05\x04\x00", b"SONAR PING360\r\nMAC Address:- 54-10-EC\r\nIP Address:- 127.0.0.1\r\n",
          b"SONAR PING360\r\nMAC Address:- 54-10-EC-00-00-09\r\n", b"hello",
          b"SONAR PING360  \r\nBlue Robotics\r\nMAC Address:- 54-10-EC-00-00-0A\r\nIP Address:- 127.000.000.001\r\n"):
    s.sendto(r, peer)
print("sent 5")
PY
FEEDPID=$!
sleep 0.3
"$B/sonard" --discover --discover-to "127.0.0.1:$PORT" --discover-data-port $((PORT + 1)) --discover-seconds 1 \
    > "$T/d3.out" 2> "$T/d3.err"
rc=$?
wait $FEEDPID; FEEDPID=""
cat "$T/d3.out" "$T/d3.err"
check "four malformed replies named (binary, short MAC, no IP line, not a Ping360), the good one listed, exit 0" sh -c "
test $rc -eq 0 &&
test \$(grep -c 'reply from 127.0.0.1:$PORT ignored' '$T/d3.err') -eq 4 &&
grep -q 'not text: byte 2 is 0x00' '$T/d3.err' && grep -q \"MAC '54-10-EC'\" '$T/d3.err' &&
grep -q \"no 'IP Address:-' line\" '$T/d3.err' && grep -q 'not a Ping360' '$T/d3.err' &&
test \$(grep -c '^127.0.0.1 ' '$T/d3.out') -eq 1 && grep -q '54-10-EC-00-00-0A  ?' '$T/d3.out' &&
grep -q 'did not answer device_information' '$T/d3.err'"

# 4. Nobody there: exit 1, said; and a bad address is refused by name.
"$B/sonard" --discover --discover-to "127.0.0.1:$((PORT + 2))" --discover-seconds 0.5 > "$T/d4.out" 2> "$T/d4.err"
rc=$?
check "no Ping360 answering: exit 1, '0 Ping360s found', nothing listed" sh -c "
test $rc -eq 1 && grep -q '0 Ping360s found in 0.5 s' '$T/d4.err' && ! test -s '$T/d4.out'"
"$B/sonard" --discover --discover-to "localhost" > "$T/d5.out" 2>&1
rc=$?
check "--discover-to localhost is refused (exit 2), naming the form" sh -c "test $rc -eq 2 && grep -q \"'localhost' is not IPV4:PORT\" '$T/d5.out'"
"$B/sonard" --discover --replay x.csv > "$T/d6.out" 2>&1
rc=$?
check "--discover with --replay is refused (exit 2)" sh -c "test $rc -eq 2 && grep -q 'discover lists the sonars and exits' '$T/d6.out'"

echo "discover: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
