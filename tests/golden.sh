#!/bin/sh
# golden.sh -- replay JSON of every simulated scene and both AquaScan recordings into DIR, for a before/after diff of a refactor.
# Usage: sh tests/golden.sh BUILD_DIR OUT_DIR  (AquaScan skipped, saying so, when ../shared is absent)
# tests/golden_check.sh compares their hashes with tests/golden.sha256 (make test) or rewrites it (make golden-update).
set -eu
B=${1:-build}; O=${2:?usage: golden.sh BUILD_DIR OUT_DIR}
R=${SONARD_REAL_DATA:-../shared/data/real}
mkdir -p "$O"
"$B/sonar-sim" --scene pool --out "$O/pool.csv" --truth "$O/pool.json" >/dev/null
"$B/sonar-sim" --scene open --seed 7 --out "$O/open.csv" --truth "$O/open.json" >/dev/null
for cfg in "default:" "m55:--median 5x5" "study:--background range --bg-margin 0" "study55:--median 5x5 --background range --bg-margin 0" "range:--background range" \
           "preset:--config docs/presets/occupied-pool.conf"; do
    name=${cfg%%:*}; args=${cfg#*:}
    for s in pool open; do
        # shellcheck disable=SC2086
        "$B/sonard" --replay "$O/$s.csv" --json --quiet --log-level warn $args > "$O/$s.$name.jsonl"
    done
done
# The other scenes under the default, and as the evaluation runs the tracking ones.
for s in moving sector occupied far still; do
    "$B/sonar-sim" --scene $s --out "$O/$s.csv" --truth "$O/$s.json" >/dev/null
    "$B/sonard" --replay "$O/$s.csv" --json --quiet --log-level warn > "$O/$s.default.jsonl"
done
for s in moving sector; do
    "$B/sonard" --replay "$O/$s.csv" --json --quiet --log-level warn --min-points 8 > "$O/$s.mp8.jsonl"
done
"$B/sonar-sim" --scene vehicle --out "$O/vehicle.csv" --truth "$O/vehicle.json" --pose-out "$O/vehicle.pose.csv" >/dev/null
"$B/sonard" --replay "$O/vehicle.csv" --json --quiet --log-level warn --pose "$O/vehicle.pose.csv" > "$O/vehicle.pose.jsonl"
"$B/sonard" --replay "$O/vehicle.csv" --json --quiet --log-level warn > "$O/vehicle.body.jsonl"
if [ -d "$R/aquascan" ]; then
    python3 tools/data/aquascan2csv.py "$R/aquascan" --out "$O/aq" --range 15 >/dev/null
    for s in sonar4 sonar11; do
        "$B/sonard" --replay "$O/aq/$s.csv" --json --quiet --log-level warn > "$O/$s.default.jsonl"
        "$B/sonard" --replay "$O/aq/$s.csv" --json --quiet --log-level warn --config docs/presets/occupied-pool.conf > "$O/$s.preset.jsonl"
    done
else
    echo "golden: AquaScan skipped: $R is absent"
fi
rm -rf "$O/aq" "$O"/*.csv
ls "$O" | wc -l
