#!/bin/sh
# view_cost.sh -- `make view-cost`: the view server's share of one Raspberry Pi 4 core with two pages drawing beams (the
# full view and Cockpit's fan tile) and Cockpit's status tile open, estimated as pi_cost.sh estimates sonard's: valgrind's
# callgrind counts the instructions the server (CPython and its C) runs while sonard replays the pool scene onto a udpm
# bus in a network namespace of its own, less the server's start and stop, per beam received; at the Ping360's fastest
# 50 beams a second, x 1.5 for ARM code at CPI 2 on a 1.5 GHz A72. The replay is slowed (valgrind runs the server some 50
# times slower) so nothing is dropped: the per-second costs (the view's ticker, status) are then shared by fewer beams
# than at 50 a second, so the estimate is high, not low. Usage: sh tools/bench/view_cost.sh BUILD
set -eu
B=${1:-build}
T=$(mktemp -d /tmp/sonard-viewcost.XXXXXX)
trap 'rm -rf "$T"' EXIT
command -v valgrind > /dev/null || { echo "view_cost: valgrind is missing (apt-get install valgrind)" >&2; exit 2; }
"$B/sonar-sim" --scene pool --out "$T/pool.csv" --truth "$T/pool.json" > /dev/null
head -n 1601 "$T/pool.csv" > "$T/part.csv"   # the metadata line and 1600 beams
URL='udpm://239.255.76.67:7667?ttl=0'
PY=.venv-view/bin/python
cat > "$T/run.sh" <<EOS
set -eu
ip link set lo up && ip route add 224.0.0.0/4 dev lo
cg() { valgrind --tool=callgrind --callgrind-out-file="\$1" $PY tools/view/sonar_view.py --lcm '$URL' --listen 127.0.0.1:8362 --types "$B/lcm/python" > /dev/null 2> "\$1.err" & echo \$!; }
up() { for i in \$(seq 1 240); do curl -sf http://127.0.0.1:8362/health > /dev/null && return 0; sleep 0.5; done; return 1; }
# stopped, and gone (not a child of this shell: wait cannot)
down() { kill -INT \$1; while kill -0 \$1 2> /dev/null; do sleep 0.5; done; }
# start and stop alone
V=\$(cg "$T/cg.start"); up; down \$V
# the pages, sonard replaying
V=\$(cg "$T/cg.run"); up
$PY tools/bench/view_cost.py --url ws://127.0.0.1:8362/ws --seconds 130 > "$T/pages.json" & P=\$!
sleep 3
"$B/sonard" --replay "$T/part.csv" --replay-speed 0.6 --quiet --log-level warn --lcm '$URL' 2> "$T/sonard.err"
wait \$P
curl -s http://127.0.0.1:8362/health > "$T/health.json"
down \$V
EOS
unshare -rn sh "$T/run.sh"
ir() { sed -n 's/.*Collected *: *\([0-9]*\).*/\1/p;s/^summary: *\([0-9]*\).*/\1/p' "$1" | head -n 1; }
start=$(ir "$T/cg.start")
total=$(ir "$T/cg.run")
python3 - "$T/pages.json" "$T/health.json" "$start" "$total" <<'EOP'
import json, sys
pages, health = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
start, total = int(sys.argv[3]), int(sys.argv[4])
beams = health["counts"]["beams"]
per = (total - start) / beams
share = per * 1.5 * 2 * 50 / 1.5e9 * 100
print(f"view_cost: {per:.0f} host instructions a beam in the view server (callgrind; {beams} beams in, "
      f"{health['counts']['dropped']} dropped; pages got {[p['beams'] for p in pages]} beams and {[p['texts'] for p in pages]} texts); "
      f"at 50 beams/s on a 1.5 GHz A72, x 1.5 for ARM code at CPI 2: {share:.1f} % of one core (target <= 10 %)")
EOP
