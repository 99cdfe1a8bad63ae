#!/bin/sh
# golden.sh -- replay JSON of every simulated scene and both AquaScan recordings into DIR, for a before/after diff of a refactor.
# Usage: sh tests/golden.sh BUILD_DIR OUT_DIR  (AquaScan skipped, saying so, when ../shared is absent)
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
        "$B/sonard" --replay "$O/$s.csv" --json --quiet $args > "$O/$s.$name.jsonl"
    done
done
if [ -d "$R/aquascan" ]; then
    python3 tools/aquascan2csv.py "$R/aquascan" --out "$O/aq" --range 15 >/dev/null
    for s in sonar4 sonar11; do
        "$B/sonard" --replay "$O/aq/$s.csv" --json --quiet > "$O/$s.default.jsonl"
        "$B/sonard" --replay "$O/aq/$s.csv" --json --quiet --config docs/presets/occupied-pool.conf > "$O/$s.preset.jsonl"
    done
else
    echo "golden: AquaScan skipped: $R is absent"
fi
rm -rf "$O/aq" "$O"/*.csv
ls "$O" | wc -l
