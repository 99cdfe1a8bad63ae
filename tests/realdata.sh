#!/bin/sh
# realdata.sh -- converters and replay on the real Ping360 recordings in ../shared/data/real (read there, never copied).
# Skips, saying why, when ../shared is absent. Ends with "N passed, N failed".
set -u
B=${1:-build}
R=${SONARD_REAL_DATA:-../shared/data/real}
if [ ! -d "$R/aquascan" ] || [ ! -f "$R/pingviewer_noah/test_ping_log.decoded" ]; then
    echo "realdata: SKIPPED: $R is absent (the real recordings are not in this repository: licence unclear)"
    echo "realdata: 0 passed, 0 failed, 1 skipped"
    exit 0
fi
T=$(mktemp -d /tmp/sonard-real.XXXXXX)
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"

# Ping Viewer .bin -> CSV: a log built from the real noah beams, frame-unaligned chunks, junk first.
for enc in utf16 utf8; do
    n=$(python3 tests/make_pvbin.py "$R/pingviewer_noah/test_ping_log.decoded" "$T/20220822-200542039.bin" \
        $( [ $enc = utf8 ] && echo --utf8 ) --tools "$R/tools")
    "$B/pvbin2csv" "$T/20220822-200542039.bin" "$T/noah.csv" 2> "$T/pv.err"
    check "Ping Viewer .bin ($enc) -> CSV: all $n real beams recovered, samples identical" python3 - "$R" "$T/noah.csv" <<'PY'
import sys, csv
sys.path.insert(0, sys.argv[1] + "/tools")
import parse_pingviewer_decoded as p
want = [r for r in p.rows(sys.argv[1] + "/pingviewer_noah/test_ping_log.decoded") if r.get("consistent")]
got = list(csv.reader(open(sys.argv[2])))
assert len(got) == len(want), (len(got), len(want))
for w, g in zip(want, got):
    assert int(g[2]) == w["angle"]
    assert bytes(int(x) for x in g[3].split()) == w["samples"]
    assert "sample_period=%d" % w["sample_period"] in g
print(len(got), "beams match")
PY
done
check "the converted Ping Viewer log replays (2 m range from its metadata)" sh -c "'$B/sonard' --replay '$T/noah.csv' --quiet --json | grep -c sweep | grep -qx 2"
head -c 5000 "$T/20220822-200542039.bin" > "$T/cut.bin"
"$B/pvbin2csv" "$T/cut.bin" "$T/cut.csv" 2> "$T/cut.err"
check "a truncated .bin: named record and byte, the beams before it kept" sh -c "grep -q 'truncated at byte' '$T/cut.err' && test -s '$T/cut.csv'"

# AquaScan text matrices + labels -> CSV + truth.
python3 tools/aquascan2csv.py "$R/aquascan" --out "$T/aq" --range 15 > "$T/aq.out"
check "AquaScan -> CSV: 51 sweeps and 237 labelled people (2 sweeps have no label file)" sh -c "grep -q 'sonar4: 30 sweeps (0 without labels, not scored), 146' '$T/aq.out' && grep -q 'sonar11: 21 sweeps (2 without labels, not scored), 91' '$T/aq.out'"
for s in sonar4 sonar11; do
    "$B/sonard" --replay "$T/aq/$s.csv" --json --quiet > "$T/$s.jsonl"
    check "AquaScan $s replays with one sonard sweep per recorded sweep" \
        test "$(wc -l < "$T/$s.jsonl")" -eq "$(python3 -c "import json;print(len(json.load(open('$T/aq/$s.truth.json'))['sweeps']))")"
done
echo "realdata: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
