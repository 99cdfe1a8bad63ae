#!/bin/sh
# bgfile.sh -- the recorded background end to end: an empty pool recorded and loaded finds people there from the first
# ping; a damaged, foreign or mismatched file is refused by name and learning starts fresh; a save that fails midway
# leaves the previous file whole. Usage: sh tests/bgfile.sh BUILD_DIR. Ends with "N passed, N failed".
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-bgfile.XXXXXX)
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"

# The occupied pool (five people in the water from the first ping) and the same pool empty, another speckle seed.
"$B/sonar-sim" --scene occupied --out "$T/occ.csv" --truth "$T/occ.json" > /dev/null
"$B/sonar-sim" --scene occupied --empty --seed 5 --sweeps 10 --out "$T/empty.csv" --truth "$T/empty.json" > /dev/null
"$B/sonard" --replay "$T/empty.csv" --quiet --log-level warn --background per-angle --background-save "$T/pa.bg"; rc=$?
check "record the empty pool (per-angle): exit 0, a file" sh -c "test $rc -eq 0 && test -s '$T/pa.bg'"
"$B/sonard" --replay "$T/empty.csv" --background-save "$T/auto.bg" 2> "$T/err" > /dev/null
check "record the empty pool (auto): said" grep -q "background saved to $T/auto.bg" "$T/err"
check "no temporary file left beside it" sh -c "! ls '$T' | grep -q '\.tmp\.'"

# People from the first ping: a per-angle background learns them, a recorded empty pool does not.
"$B/sonard" --replay "$T/occ.csv" --json --background per-angle > "$T/fresh.jsonl" 2> /dev/null
"$B/sonard" --replay "$T/occ.csv" --json --background per-angle --background-load "$T/pa.bg" > "$T/loaded.jsonl" 2> "$T/err"
check "loading is said with its geometry" grep -q "background: loaded, 500 samples over 15.000 m" "$T/err"
fresh=$(python3 tools/eval/score.py "$T/occ.json" "$T/fresh.jsonl" | sed -n 's/.*recall \([0-9.]*\).*/\1/p' | head -1)
check "occupied pool, per-angle from an empty-pool recording: F1 >= 0.93 (learnt afresh: recall $fresh)" \
    python3 tools/eval/score.py "$T/occ.json" "$T/loaded.jsonl" --min-f1 0.93 --label "  loaded: "
check "... where learning afresh loses the people there from the first ping (recall < 0.5)" \
    awk -v r="$fresh" 'BEGIN { exit !(r < 0.5) }'
"$B/sonard" --replay "$T/occ.csv" --json --background-load "$T/auto.bg" > "$T/auto.jsonl" 2> /dev/null
check "occupied pool, default (auto) from its recording: F1 >= 0.93" \
    python3 tools/eval/score.py "$T/occ.json" "$T/auto.jsonl" --min-f1 0.93 --label "  auto loaded: "

# The clutter map (issue 51) rides after the image: loaded and said; a file without one (written before sonard kept
# one) loads and says so; a damaged map is refused by name and learnt afresh, the background loaded all the same.
"$B/sonard" --replay "$T/occ.csv" --json --background-load "$T/auto.bg" > /dev/null 2> "$T/err"
check "the saved file carries a clutter map: loaded and said" grep -q "clutter map: loaded, learnt over 10 looks" "$T/err"
size=$(wc -c < "$T/auto.bg")
head -c $((size - 1628)) "$T/auto.bg" > "$T/nomap.bg"
"$B/sonard" --replay "$T/occ.csv" --json --background-load "$T/nomap.bg" > "$T/nomap.jsonl" 2> "$T/err"
check "a file without a clutter map (as before issue 51): loads, said, the map learnt as it runs" \
    sh -c "grep -q 'background: loaded' '$T/err' && grep -q 'clutter map: none in the file' '$T/err'"
cp "$T/auto.bg" "$T/badmap.bg"
printf '\377' | dd of="$T/badmap.bg" bs=1 seek=$((size - 100)) conv=notrunc 2> /dev/null
"$B/sonard" --replay "$T/occ.csv" --json --background-load "$T/badmap.bg" > "$T/badmap.jsonl" 2> "$T/err"
check "a damaged clutter map: refused by name, learnt afresh; the background loaded, output as without a map" \
    sh -c "grep -q 'background: loaded' '$T/err' && grep -q 'clutter map: refused, damaged .*learnt afresh' '$T/err' && cmp -s '$T/badmap.jsonl' '$T/nomap.jsonl'"

# Bad files: named, the run goes on and learns afresh (its output equal to a run with no file).
"$B/sonard" --replay "$T/occ.csv" --json > "$T/none.jsonl" 2> /dev/null
refused() { # what file word
    "$B/sonard" --replay "$T/occ.csv" --json --background-load "$2" > "$T/r.jsonl" 2> "$T/err"; rc=$?
    check "$1: refused by name ('$3'), exit 0, output as with no file" \
        sh -c "test $rc -eq 0 && grep -q -- '--background-load $2: .*$3.*learns afresh' '$T/err' && cmp -s '$T/r.jsonl' '$T/none.jsonl'"
}
head -c 100000 "$T/auto.bg" > "$T/trunc.bg"
refused "a truncated file" "$T/trunc.bg" "truncated"
cp "$T/auto.bg" "$T/flip.bg"
printf '\377' | dd of="$T/flip.bg" bs=1 seek=50000 conv=notrunc 2> /dev/null
refused "a damaged file (one byte)" "$T/flip.bg" "checksum"
refused "another kind of file" "$T/occ.csv" "not a sonard background file"
refused "a missing file" "$T/nope.bg" "No such file"
"$B/sonard" --replay "$T/occ.csv" --json --background per-angle --background-load "$T/auto.bg" > /dev/null 2> "$T/err"
check "a file learnt in auto mode loads into a per-angle background (a site's model is per angle)" \
    grep -q "background: loaded, 500 samples over 15.000 m" "$T/err"
"$B/sonard" --replay "$T/occ.csv" --json --median 3 --background-load "$T/auto.bg" > /dev/null 2> "$T/err"
check "a file learnt after another filter: refused by name" grep -q "filter: learnt after median 5" "$T/err"
# Another range: the first beam says so, the background restarts there.
"$B/sonar-sim" --scene pool --sweeps 2 --out "$T/pool.csv" --truth "$T/pool.json" > /dev/null
"$B/sonard" --replay "$T/pool.csv" --json > "$T/pool_none.jsonl" 2> /dev/null
"$B/sonard" --replay "$T/pool.csv" --json --background-load "$T/auto.bg" > "$T/pool_r.jsonl" 2> "$T/err"
check "a file of another range and samples: refused at the first beam, output as with no file" \
    sh -c "grep -q 'recorded at 500 samples over 15.000 m.*gives 1200 over 12.000 m.*not used; the background learns afresh' '$T/err' && cmp -s '$T/pool_r.jsonl' '$T/pool_none.jsonl'"
"$B/sonard" --replay "$T/occ.csv" --background range --background-save "$T/x.bg" > /dev/null 2> "$T/err"; rc=$?
check "--background-save with --background range: exit 2, named" sh -c "test $rc -eq 2 && grep -q 'go with --background auto or per-angle' '$T/err'"
# A world-frame model is not saved (a moving vehicle): said, exit 1.
"$B/sonar-sim" --scene vehicle --sweeps 2 --out "$T/veh.csv" --truth "$T/veh.json" --pose-out "$T/veh.pose" > /dev/null
"$B/sonard" --replay "$T/veh.csv" --pose "$T/veh.pose" --quiet --background-save "$T/veh.bg" 2> "$T/err"; rc=$?
check "a world-frame model: not saved, said, exit 1" sh -c "test $rc -eq 1 && grep -q 'world-frame model' '$T/err' && test ! -e '$T/veh.bg'"

# A save that fails midway (a file-size limit below the image) leaves the previous file whole.
cp "$T/auto.bg" "$T/keep.bg"
(ulimit -f 64; "$B/sonard" --replay "$T/occ.csv" --quiet --background-save "$T/keep.bg" 2> "$T/err"); rc=$?
check "a failed save: exit 1, said, the previous file whole and no temporary left" \
    sh -c "test $rc -eq 1 && grep -q 'the previous file is unchanged' '$T/err' && cmp -s '$T/keep.bg' '$T/auto.bg' && ! ls '$T' | grep -q '\.tmp\.'"
mkdir "$T/ro" && chmod 500 "$T/ro"
if [ "$(id -u)" -ne 0 ]; then
    "$B/sonard" --replay "$T/occ.csv" --quiet --background-save "$T/ro/x.bg" 2> "$T/err"; rc=$?
    check "a folder that cannot be written: exit 1, named" sh -c "test $rc -eq 1 && grep -q 'ro/x.bg' '$T/err'"
fi

echo "bgfile: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
