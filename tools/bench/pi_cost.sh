#!/bin/sh
# pi_cost.sh -- `make pi-cost`: sonard's share of one Raspberry Pi 4 core (Cortex-A72, 1.5 GHz) at the Ping360's
# fastest beam rate, estimated from instructions: valgrind's callgrind counts the host build's instructions for a whole
# replay (the 1200-sample pool scene: CSV parsing, median, background, CFAR, detection, tracking, JSON and every beam
# and sweep encoded and published on LCM memq), less start-up, per beam. The A72 estimate takes the same count for
# ARM code (x FACTOR, 1.5: a wide margin for 32-bit ARM code against x86-64) at CPI (2: the A72 sustains more than
# one instruction a cycle on such loops; 2 cycles each is a bound, not a guess). Usage: sh tools/bench/pi_cost.sh BUILD
set -eu
B=${1:-build}
T=$(mktemp -d /tmp/sonard-picost.XXXXXX)
trap 'rm -rf "$T"' EXIT
command -v valgrind > /dev/null || { echo "pi_cost: valgrind is missing (apt-get install valgrind)" >&2; exit 2; }
"$B/sonar-sim" --scene pool --out "$T/pool.csv" --truth "$T/pool.json" > /dev/null
ir() { valgrind --tool=callgrind --callgrind-out-file="$T/cg" "$@" 2>&1 > /dev/null | sed -n 's/.*I *refs: *//p' | tr -d ,; }
total=$(ir "$B/sonard" --replay "$T/pool.csv" --quiet --log-level warn --json --lcm memq://)
start=$(ir "$B/sonard" --version)
beams=$(wc -l < "$T/pool.csv")
awk -v t="$total" -v s="$start" -v n="$beams" 'BEGIN {
    per = (t - s) / n; rate = 50; hz = 1.5e9; factor = 1.5; cpi = 2
    share = per * factor * cpi * rate / hz * 100
    printf "pi_cost: %.0f host instructions a beam (1200 samples, %d beams, callgrind); at %d beams/s on a 1.5 GHz A72, " \
           "x %.1f for ARM code at CPI %d: %.2f %% of one core (target <= 2 %%)\n", per, n, rate, factor, cpi, share }'
