#!/bin/sh
# stalls.sh -- the live suites on a machine that pauses or is busy: `stalls` freezes each suite's whole session (every
# process of it, as a VM's pause freezes them all at once: SIGSTOP, then SIGCONT) for STALL_MS every STALL_EVERY s;
# `load` runs each suite ROUNDS times while niced busy loops keep every core busy. A suite must pass as it does alone.
# Usage: sh tests/stalls.sh stalls|load [SUITE...] (make targets; default: the live suites).
# Ends with "N passed, N failed"; each suite's log is kept in build/stalls/.
set -u
mode=${1:-stalls}
[ $# -gt 0 ] && shift
suites=${*:-live mavlink scan-test mcap passive-test view-test cockpit-test}
STALL_MS=${STALL_MS:-150}
STALL_EVERY=${STALL_EVERY:-3}
ROUNDS=${ROUNDS:-3}
L=build/stalls
mkdir -p "$L"
pass=0 fail=0
HOGS=""
trap 'for h in $HOGS; do kill $h 2> /dev/null; done' EXIT
case $mode in
stalls) rounds=1 ;;
load)
    rounds=$ROUNDS
    for i in $(seq "$(nproc)"); do nice -n 19 sh -c 'while :; do :; done' & HOGS="$HOGS $!"; done
    echo "stalls: $(nproc) niced busy loops keep every core busy"
    ;;
*) echo "stalls.sh: $mode: stalls or load" >&2; exit 2 ;;
esac
# The freezer: sleeps without holding anything, then stops every process of session $1 and continues them.
freezer() {
    n=0
    while kill -0 "$1" 2> /dev/null; do
        sleep "$(awk -v e="$STALL_EVERY" -v m="$STALL_MS" 'BEGIN { print e - m / 1000 }')"
        pkill -STOP -s "$1" 2> /dev/null || break
        sleep "$(awk -v m="$STALL_MS" 'BEGIN { print m / 1000 }')"
        pkill -CONT -s "$1" 2> /dev/null
        n=$((n + 1))
        echo $n > "$2"
    done
}
for s in $suites; do
    r=1
    while [ $r -le $rounds ]; do
        log=$L/$mode-$s-$r.log
        t0=$(date +%s)
        # A session of its own, so that everything the suite starts (under timeout(1) too) is frozen with it.
        setsid make --no-print-directory "$s" > "$log" 2>&1 < /dev/null &
        pid=$!
        fp=""
        echo 0 > "$L/$mode-$s.freezes"
        [ "$mode" = stalls ] && { freezer "$pid" "$L/$mode-$s.freezes" & fp=$!; }
        wait $pid; rc=$?
        [ -n "$fp" ] && { kill $fp 2> /dev/null; wait $fp 2> /dev/null; pkill -CONT -s "$pid" 2> /dev/null; }
        last=$(grep -E '[0-9]+ passed, [0-9]+ failed' "$log" | tail -1)
        what="$s"
        [ "$mode" = stalls ] && what="$s, frozen $(cat "$L/$mode-$s.freezes") times for $STALL_MS ms every $STALL_EVERY s"
        [ "$mode" = load ] && what="$s, round $r of $rounds under load"
        if [ $rc -eq 0 ]; then
            pass=$((pass + 1)); echo "[  PASS  ] $what ($(( $(date +%s) - t0 )) s: $last)"
        else
            fail=$((fail + 1)); echo "[  FAIL  ] $what ($(( $(date +%s) - t0 )) s: $last; $log)"
            grep -E 'FAIL|Error|error' "$log" | head -8 | sed 's/^/    /'
        fi
        grep -h 'loop: host stalls' "$log" 2> /dev/null | sort | uniq -c | sort -rn | head -3 | sed 's/^/    /'
        r=$((r + 1))
    done
done
echo "stalls ($mode): $pass passed, $fail failed"
[ "$fail" -eq 0 ]
