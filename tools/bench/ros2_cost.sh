#!/bin/sh
# ros2_cost.sh -- `make ros2-cost` (and the end of `make bench`): the ROS 2 bridge's cost and its behaviour flat out.
# 1. Its share of one Raspberry Pi 4 core at 50 beams a second, estimated as view_cost.sh estimates the view's: valgrind's
#    callgrind counts the instructions the bridge (CPython, rclpy, DDS) runs while sonard replays the pool scene onto a
#    udpm bus and an rclpy node takes every topic, less its start and stop and less what it costs idle a second (DDS's
#    threads, the loop's wakes: measured alone), per beam received; at 50 beams a second plus the idle second, x 1.5
#    for ARM code at CPI 2 on a 1.5 GHz A72. The replay is slowed so that nothing is lost under valgrind (checked:
#    the bridge's own count of LCM messages lost). The pool scene's beams are 41 ms apart, so its images (image_hz
#    by sonard's clock) come one per 5 beams, not one per 10 as at 50 beams a second: high, not low. Against sonard's
#    own instructions a beam on the same beams (pi_cost.sh's method), as a ratio.
# 2. At the replay's top speed (sonard --replay-speed 0, three times over): what the bridge received, what it counted
#    lost, and what was lost at the end of each burst (no later message shows those: sent less the two; sent is the
#    same replay logged to a file, counted), nothing queued without bound (its peak RSS after one replay and after
#    three).
# All in a network namespace of its own. Usage: sh tools/bench/ros2_cost.sh BUILD
set -eu
B=${1:-build}
T=$(mktemp -d /tmp/sonard-ros2cost.XXXXXX)
trap '[ -n "${KEEP:-}" ] || rm -rf "$T"' EXIT
command -v valgrind > /dev/null || { echo "ros2_cost: valgrind is missing (apt-get install valgrind)" >&2; exit 2; }
PY=.venv-ros2/bin/python
[ -x "$PY" ] || { echo "ros2_cost: no .venv-ros2 (make ros2)" >&2; exit 2; }
. tests/lib.sh
"$B/sonar-sim" --scene pool --out "$T/pool.csv" --truth "$T/pool.json" > /dev/null
head -n 600 "$T/pool.csv" > "$T/part.csv"
URL='udpm://239.255.76.67:7667?ttl=0'
BRIDGE="tools/ros2/sonard_ros2.py --lcm $URL --types $B/lcm/python"
NS="--ros-args -r __ns:=/sonar"
# What sonard sends for one replay of the whole scene, by channel, from the same replay logged to a file.
"$B/sonard" --replay "$T/pool.csv" --quiet --log-level warn --lcm "file://$T/sent.lcm?mode=w"
python3 -c "
import importlib.machinery, sys
m = importlib.machinery.SourceFileLoader('l', 'tools/data/lcm2mcap').load_module()
print(sum(1 for _ in m.read_events(open('$T/sent.lcm', 'rb'))))" > "$T/sent.n"
cat > "$T/run.sh" <<EOS
set -eu
ip link set lo up && ip route add 224.0.0.0/4 dev lo
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
# --trace-children: the ROS wheels' bootstrapper re-executes Python with its library path set
CG="valgrind --tool=callgrind --trace-children=yes --callgrind-out-file"
# start and stop alone, then idle for 20 s more (DDS's threads and the loop's wakes cost by the second)
\$CG="$T/cg.start.%p" $PY $BRIDGE --max-seconds 1 $NS > /dev/null 2> "$T/cg.start.err"
\$CG="$T/cg.idle.%p" $PY $BRIDGE --max-seconds 21 $NS > /dev/null 2> "$T/cg.idle.err"
# the scene's first 600 beams at half their pace within its 80 s, an rclpy node taking every topic
\$CG="$T/cg.run.%p" $PY $BRIDGE --max-seconds 81 $NS > /dev/null 2> "$T/cg.run.err" & V=\$!
i=0; while ! grep -q 'in frame' "$T/cg.run.err" 2> /dev/null && [ \$i -lt 240 ]; do sleep 0.5; i=\$((i + 1)); done
$PY tools/bench/ros2_listen.py --seconds 60 > "$T/listen.json" & L=\$!
sleep 3
"$B/sonard" --replay "$T/part.csv" --replay-speed 0.5 --quiet --log-level warn --lcm '$URL'
wait \$L
wait \$V
# flat out: the whole scene at once, three times, the bridge plain
$PY $BRIDGE $NS > /dev/null 2> "$T/fast.err" & P=\$!
i=0; while ! grep -q 'in frame' "$T/fast.err" 2> /dev/null && [ \$i -lt 60 ]; do sleep 0.5; i=\$((i + 1)); done
$PY tools/bench/ros2_listen.py --seconds 60 > "$T/fast.json" & L=\$!
sleep 3
for i in 1 2 3; do
    "$B/sonard" --replay "$T/pool.csv" --quiet --log-level warn --lcm '$URL'
    sleep 3
    [ \$i -eq 1 ] && grep VmHWM /proc/\$P/status > "$T/hwm1"
done
grep VmHWM /proc/\$P/status > "$T/hwm3"
kill -TERM \$P; wait \$P || true
kill -TERM \$L 2> /dev/null; wait \$L || true
EOS
$NETNS sh "$T/run.sh"
# the instructions of every process a run made (the bootstrapper's first, then the one it executed)
ir() { cat "$1".[0-9]* | sed -n 's/^summary: *\([0-9]*\).*/\1/p' | awk '{ s += $1 } END { printf "%.0f\n", s }'; }
sonard_ir() { valgrind --tool=callgrind --callgrind-out-file="$T/cg.sd" "$@" 2>&1 > /dev/null | sed -n 's/.*I *refs: *//p' | tr -d ,; }
sd_total=$(sonard_ir "$B/sonard" --replay "$T/part.csv" --quiet --log-level warn --json --lcm memq://)
sd_start=$(sonard_ir "$B/sonard" --version)
python3 - "$(ir "$T/cg.start")" "$(ir "$T/cg.run")" "$sd_total" "$sd_start" "$(wc -l < "$T/part.csv")" "$T" \
    "$(ir "$T/cg.idle")" <<'EOP'
import json, re, sys
start, total, sd_total, sd_start, sd_beams, t, idle = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), \
    int(sys.argv[4]), int(sys.argv[5]), sys.argv[6], int(sys.argv[7])
def summary(path):
    line = [l for l in open(path) if l.startswith("sonard_ros2: LCM in:")][-1]
    got = dict((k, int(v)) for k, v in re.findall(r"(SONAR_[A-Z]+) (\d+)", line.split(";")[0]))
    lost = int(re.search(r"(\d+) lost on the way", line).group(1))
    return got, lost, line.strip()
got, lost, _ = summary(f"{t}/cg.run.err")
beams = got.get("SONAR_BEAM", 0)
per_s = (idle - start) / 20          # idle, a second
per = (total - start - 80 * per_s) / max(beams, 1)  # the work a beam brings
sd_per = (sd_total - sd_start) / sd_beams
share = (per * 50 + per_s) * 1.5 * 2 / 1.5e9 * 100
listen = json.load(open(f"{t}/listen.json"))
print(f"ros2_cost: the bridge (callgrind): {per:.0f} host instructions a beam ({beams} beams in, {lost} LCM messages "
      f"lost; a node took {listen}), and {per_s:.0f} a second idle (DDS's threads, the loop's wakes); sonard's own on "
      f"the same beams {sd_per:.0f} a beam: the bridge's work {per / sd_per:.1f}x sonard's; at 50 beams/s on a 1.5 GHz "
      f"A72, x 1.5 for ARM code at CPI 2: {share:.1f} % of one core")
fgot, flost, line = summary(f"{t}/fast.err")
sent = 3 * int(open(f"{t}/sent.n").read())
hwm = [int(re.search(r"(\d+)", open(f"{t}/{f}").read()).group(1)) for f in ("hwm1", "hwm3")]
took = sum(fgot.values())
print(f"ros2_cost: flat out (3 replays of the scene at once, {sent} LCM messages sent): the bridge received {took}, "
      f"counted {flost} lost (gaps in the senders' numbers), and {sent - took - flost} more were lost at the ends of "
      f"the bursts, where no later message shows the gap; peak RSS {hwm[0]} kB after one replay, {hwm[1]} kB after "
      f"three; a node took {json.load(open(f'{t}/fast.json'))}")
print("  " + line)
EOP
