#!/bin/sh
# mcu_property.sh -- each board gives the host's answer on the beams it is given, over generated cases: the simulator's
# pools (several seeds), 1- and 2-gradian steps, 500 and 600 samples, the default detector options, --min-points 10
# and the occupied-pool preset, on the an500 (Cortex-M7), H743-banks and F405 images in QEMU. Each case's co-processor
# sweeps must equal `sonard --replay` of the beams the firmware forwarded (tests/mcu_equal.py); a case the board
# cannot hold must be refused when configured, by name (sonard exits 2), never answered differently.
# The cases are drawn in a fixed order from every combination; CASES of them run (CI: a few; by hand: many).
# Usage: sh tests/mcu_property.sh BUILD_DIR [CASES] [SWEEPS]. Loopback only, every run bounded in time.
# Ends with "N passed, N failed".
set -u
B=${1:-build}
CASES=${2:-6}
SWEEPS=${3:-2}
T=$(mktemp -d /tmp/sonard-mcuprop.XXXXXX)
PORT=$(( 23000 + ($$ % 17000) ))
PIDS=""
trap 'for p in $PIDS; do kill $p 2>/dev/null; done; rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
if ! command -v qemu-system-arm > /dev/null 2>&1; then
    echo "mcu-property: SKIPPED: qemu-system-arm is not installed (make deps installs it)"
    echo "mcu-property: 0 passed, 0 failed, 1 skipped"
    exit 0
fi
started=$(date +%s)
python3 - "$CASES" > "$T/cases" <<'PY'
import itertools, random, sys
boards = ["f405", "an500", "h743"]
combos = list(itertools.product([1, 2, 3], ["pool", "occupied", "laps", "lanes", "open"],
                                ["default", "min-points-10", "occupied-pool"], [500, 600], [2, 1]))
# Each board's combinations in a fixed shuffled order, the boards taken in turn: any first few cases cover all three.
per = []
for b in boards:
    c = combos[:]
    random.Random(50 + len(per)).shuffle(c)
    if b == "f405":  # what it holds (500 samples, 2-gradian steps) and what it must refuse, in turn
        hold = [x for x in c if x[3] == 500 and x[4] == 2]
        rest = [x for x in c if x not in hold]
        c = [x for pair in itertools.zip_longest(hold, rest) for x in pair if x is not None]
    per.append([x + (b,) for x in c])
for k in range(int(sys.argv[1])):
    print(*per[k % 3][k // 3])
PY
while read -r seed scene opt samples step board; do
    case $board in
    f405) MACHINE=netduinoplus2; ELF=$B/mcu/sonard-f405.elf ;;
    h743) MACHINE=mps2-an500; ELF=$B/mcu/sonard-an500-h743.elf ;;
    *) MACHINE=mps2-an500; ELF=$B/mcu/sonard-an500.elf ;;
    esac
    case $opt in
    default) DOPT="" ;;
    min-points-10) DOPT="--min-points 10" ;;
    *) DOPT="--config docs/presets/$opt.conf" ;;
    esac
    # A 100-gradian sector keeps QEMU's UART (about 12 KiB/s) at a few seconds a sweep.
    OPTS="--range 12 --samples $samples --step $step --sector 150:250 $DOPT"
    name="$board-$scene-s$seed-$opt-n$samples-st$step"
    p0=$PORT p1=$((PORT + 1)); PORT=$((PORT + 2))
    "$B/sonar-feed" --listen "tcp:127.0.0.1:$p0" --scene "$scene" --seed "$seed" --pace fast --max-seconds 200 \
        2> /dev/null & fp=$!
    sleep 0.3
    qemu-system-arm -M "$MACHINE" -display none -monitor none -kernel "$ELF" \
        -serial "tcp:127.0.0.1:$p0,reconnect=1" -serial "tcp:127.0.0.1:$p1,server=on,wait=off" > "$T/$name.qemu" 2>&1 & qp=$!
    PIDS="$fp $qp"
    sleep 0.5
    # shellcheck disable=SC2086
    timeout 180 "$B/sonard" --coprocessor "tcp:127.0.0.1:$p1" $OPTS --sweeps "$SWEEPS" --json --no-lcm \
        --coprocessor-beams 1 --csv-out "$T/$name.csv" > "$T/$name.jsonl" 2> "$T/$name.err"; rc=$?
    kill $qp $fp 2> /dev/null; wait $qp $fp 2> /dev/null; PIDS=""
    # What the board's build cannot hold: the F405's 500 samples and 200 angle cells (2-gradian steps).
    why=""
    [ "$board" = f405 ] && [ "$samples" -gt 500 ] && why="samples: 200..500 on this board"
    [ "$board" = f405 ] && [ -z "$why" ] && [ "$step" -lt 2 ] && why="step: at least 400 gradians / 200 angle cells"
    if [ -n "$why" ]; then
        check "$name: refused when configured, by name ($why), sonard exits 2" \
            sh -c "test $rc -eq 2 && grep -q '$why' '$T/$name.err' || { tail -3 '$T/$name.err'; exit 1; }"
    else
        # The rows carry the range the device gave (range_m=, from its sample period): --range would override it.
        # shellcheck disable=SC2086
        "$B/sonard" --replay "$T/$name.csv" $(echo "$OPTS" | sed 's/--range [0-9.]*//') --json --quiet --log-level warn \
            > "$T/$name.replay.jsonl" 2> "$T/$name.rerr"
        check "$name: $SWEEPS sweeps equal to the host's replay of the beams the board was given" \
            sh -c "test $rc -eq 0 && test \$(wc -l < '$T/$name.jsonl') -eq $SWEEPS &&
                   python3 tests/mcu_equal.py '$T/$name.jsonl' '$T/$name.replay.jsonl' || { tail -3 '$T/$name.err'; exit 1; }"
        sed 's/^/    /' "$T/out"
    fi
done < "$T/cases"
echo "mcu-property: $(wc -l < "$T/cases") cases ($SWEEPS sweeps each) in $(( $(date +%s) - started )) s"
echo "mcu-property: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
