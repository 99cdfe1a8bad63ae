#!/bin/sh
# demo.sh -- the main job on a simulated sonar: sonar-feed plays a Ping360 in a pool, sonard drives it live,
# publishes over LCM (to a log file), and the detections are compared with the truth.
set -eu
B=${1:-build}
D=${DEMO_DIR:-$B/demo}
PORT=${DEMO_PORT:-$(( 30000 + ($$ % 20000) ))}
mkdir -p "$D"
rm -f "$D/pool.lcm"
echo "== 1. a simulated Ping360 on tcp:127.0.0.1:$PORT: 20 x 12 m pool, gate posts from sweep 2, a moving buoy from sweep 3"
echo "      (--pace fast: replies as fast as possible; --pace device follows the real ~28-92 ms per beam)"
"$B/sonar-sim" --scene pool --out "$D/pool.csv" --truth "$D/pool.truth.json" > /dev/null
"$B/sonar-feed" --listen "tcp:127.0.0.1:$PORT" --scene pool --pace fast --exit-after-motor-off --max-seconds 120 \
    --log "$D/feed.log" 2> "$D/feed.err" &
FEED=$!
trap 'kill $FEED 2>/dev/null || true' EXIT
sleep 0.3
echo "== 2. sonard drives it: 12 m, 1-gradian steps, 7 sweeps; LCM to $D/pool.lcm"
start=$(date +%s%N)
"$B/sonard" --sonar "tcp:127.0.0.1:$PORT" --range 12 --sweeps 7 --lcm "file://$PWD/$D/pool.lcm?mode=w" --publish-filtered
end=$(date +%s%N)
wait $FEED 2>/dev/null || true
echo "== 3. what went over LCM (decoded from the log with the generated Python types)"
python3 tools/data/lcm_log.py "$D/pool.lcm" summary --types "$B/lcm/python" | sed 's/^/   /'
python3 tools/data/lcm_log.py "$D/pool.lcm" status --types "$B/lcm/python" | sed 's/^/   last SONAR_STATUS: /'
echo "== 4. SONAR_DETECTIONS against the truth (a detection matches an object within 1 m)"
python3 tools/data/lcm_log.py "$D/pool.lcm" detections --types "$B/lcm/python" > "$D/pool.detections.jsonl"
python3 tools/eval/score.py "$D/pool.truth.json" "$D/pool.detections.jsonl" --verbose
echo "== 5. the study's method on the same scene, replayed from CSV (median across beams, plain subtraction)"
"$B/sonard" --replay "$D/pool.csv" --json --quiet --background range --bg-margin 0 > "$D/pool.study.jsonl"
python3 tools/eval/score.py "$D/pool.truth.json" "$D/pool.study.jsonl" --label "   study's method: " || true
echo "== live run: $(( (end - start) / 1000000 )) ms for 2800 beams; sonar-feed: $(tail -1 "$D/feed.err" | sed 's/sonar_feed: //')"
echo "   To watch it: make spy (lcm-spy with these types); on a vehicle: sonard --sonar udp:192.168.2.2:9092 (see README)"
