#!/bin/sh
# bench_mavlink.sh -- `make bench`'s MAVLink figures, measured, never pass/fail: OBSTACLE_DISTANCE's rate against the
# configured 10 Hz, its p99 and longest gap against the 100 ms period, echo to message, and the host's stalls over the
# run (sonard's own measure and the listener's). sonar-feed at device pace -> sonard --mavlink -> tests/mavlink_check.py
# on 127.0.0.1. Usage: sh tools/bench/bench_mavlink.sh BUILD_DIR [SECONDS]
set -eu
B=${1:-build}
SEC=${2:-30}
T=$(mktemp -d /tmp/sonard-benchmav.XXXXXX)
PORT=$(( 26000 + ($$ % 13000) ))
trap 'kill $fp 2> /dev/null; rm -rf "$T"' EXIT
"$B/sonar-feed" --listen "tcp:127.0.0.1:$PORT" --scene pool --max-seconds $((SEC + 30)) 2> /dev/null & fp=$!
sleep 0.3
timeout $((SEC + 20)) "$B/sonard" --sonar "tcp:127.0.0.1:$PORT" --range 12 --step 2 --no-lcm --quiet \
    --mavlink "udpin:127.0.0.1:$((PORT + 1))" 2> "$T/err" & sp=$!
.venv-mavlink/bin/python tests/mavlink_check.py --port $((PORT + 1)) --seconds "$SEC" --listen-only --out "$T/rep" > /dev/null
kill -TERM $sp; wait $sp || true
.venv-mavlink/bin/python - "$T/rep" "$T/err" <<'PY'
import json, re, sys
r = json.load(open(sys.argv[1]))
err = open(sys.argv[2]).read()
m = re.search(r"echo to message mean ([0-9.]+) ms, max ([0-9.]+) ms", err)
st = re.search(r"loop: host stalls (\d+), longest (\d+) ms, (\d+) ms in all", err)
print("MAVLink out (one run, %d OBSTACLE_DISTANCE over %.0f s; measured, never a pass/fail threshold)" % (r["od_n"], r["od_n"] / r["od_rate_hz"]))
print("%-46s %11.2f Hz %11.2f Hz %9.3fx  (the configured rate)" % ("OBSTACLE_DISTANCE rate", r["od_rate_hz"], 10.0, r["od_rate_hz"] / 10.0))
print("%-46s %11.1f ms %11.1f ms %9.2fx  (the period; ArduPilot's timeout is 500 ms)" % ("  p99 gap between messages", r["od_p99_gap_s"] * 1e3, 100.0, r["od_p99_gap_s"] * 10))
print("%-46s %11.1f ms %11.1f ms %9.2fx  (the period)" % ("  longest gap", r["od_max_gap_s"] * 1e3, 100.0, r["od_max_gap_s"] * 10))
if m:
    print("%-46s %11.1f ms %11.1f ms %9.2fx  (the period; max %.1f ms)" % ("  echo to message, mean", float(m.group(1)), 100.0, float(m.group(1)) / 100, float(m.group(2))))
if st:
    print("%-46s %11s    %11s     the listener saw %d, %.0f ms in all" % ("  host stalls (sonard's measure)", st.group(1), st.group(3) + " ms", len(r["stalls"]), r["stalled_s"] * 1e3))
PY
