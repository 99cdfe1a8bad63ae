#!/bin/sh
# demo.sh -- the main job on a simulated sonar: simulate a pool, replay it through sonard, compare with the truth.
set -eu
B=${1:-build}
D=${DEMO_DIR:-$B/demo}
mkdir -p "$D"
echo "== 1. simulate: 20 x 12 m pool, 7 sweeps of 400 beams x 1200 samples (12 m), gate posts from sweep 2, buoy from sweep 3"
"$B/sonar-sim" --scene pool --out "$D/pool.csv" --truth "$D/pool.truth.json"
ls -l "$D/pool.csv" | awk '{printf "   %s: %.1f MB, %d rows\n", $9, $5 / 1e6, 0}' | sed "s/0 rows/$(wc -l < "$D/pool.csv") rows/"
echo "== 2. replay through sonard (default: median 5, per-angle background, k-means + hull per sweep)"
start=$(date +%s%N)
"$B/sonard" --replay "$D/pool.csv"
"$B/sonard" --replay "$D/pool.csv" --json --quiet > "$D/pool.detections.jsonl"
end=$(date +%s%N)
echo "== 3. against the truth (a detection matches an object within 1 m)"
python3 tools/score.py "$D/pool.truth.json" "$D/pool.detections.jsonl" --verbose
echo "== 4. the study's method on the same file (median across beams, plain subtraction)"
"$B/sonard" --replay "$D/pool.csv" --json --quiet --background range --bg-margin 0 > "$D/pool.study.jsonl"
python3 tools/score.py "$D/pool.truth.json" "$D/pool.study.jsonl" --label "   study's method: " || true
echo "== wall time for both replays of $(wc -l < "$D/pool.csv") beams: $(( (end - start) / 1000000 )) ms; files in $D"
