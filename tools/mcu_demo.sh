#!/bin/sh
# mcu_demo.sh -- make demo's pool, detected on the emulated co-processor: sonar-feed -> QEMU's first UART (the
# firmware runs the core's driver and pipeline) -> its second UART -> sonard --coprocessor -> LCM log; scored against the
# truth. Usage: sh tools/mcu_demo.sh BUILD_DIR [an500|f405] (mps2-an500's Cortex-M7, or an STM32F405 in netduinoplus2).
set -eu
B=${1:-build}
case "${2:-an500}" in
    an500) MACHINE=mps2-an500; ELF=$B/mcu/sonard-an500.elf ;;
    f405) MACHINE=netduinoplus2; ELF=$B/mcu/sonard-f405.elf ;;
    *) echo "mcu_demo: BOARD '${2}' is not an500 or f405" >&2; exit 2 ;;
esac
D=${DEMO_DIR:-$B/mcu-demo}
PORT=${DEMO_PORT:-$(( 30000 + ($$ % 20000) ))}
mkdir -p "$D"
rm -f "$D/pool.lcm"
"$B/sonar-sim" --scene pool --out "$D/pool.csv" --truth "$D/pool.truth.json" > /dev/null
echo "== 1. a simulated Ping360 on tcp:127.0.0.1:$PORT (the pool of make demo)"
"$B/sonar-feed" --listen "tcp:127.0.0.1:$PORT" --scene pool --pace fast --max-seconds 300 --log "$D/feed.log" 2> "$D/feed.err" &
FEED=$!
QEMU_CMD="qemu-system-arm -M $MACHINE -display none -monitor none -kernel $ELF -serial tcp:127.0.0.1:$PORT,reconnect=1 -serial tcp:127.0.0.1:$((PORT + 1)),server=on,wait=off"
sleep 0.3
echo "== 2. the co-processor firmware in QEMU; UART0 is the sonar, UART1 the onboard computer. On a real board these"
echo "      are its two serial ports; here:"
echo "      $QEMU_CMD"
$QEMU_CMD > "$D/qemu.log" 2>&1 &
QEMU=$!
trap 'kill $FEED $QEMU 2>/dev/null || true' EXIT
sleep 0.5
echo "== 3. sonard --coprocessor pushes its options (12 m, 300 samples, 2-gradian steps: QEMU's UART moves ~12 KiB/s)"
echo "      and republishes the firmware's detections and status; 7 sweeps, LCM to $D/pool.lcm. An eighth of make demo's"
echo "      cells a sweep, so --min-points 4 stands for its 20"
"$B/sonard" --coprocessor "tcp:127.0.0.1:$((PORT + 1))" --range 12 --samples 300 --step 2 --sweeps 7 \
    --min-points 4 --lcm "file://$PWD/$D/pool.lcm?mode=w"
echo "== 4. what went over LCM"
python3 tools/data/lcm_log.py "$D/pool.lcm" summary --types "$B/lcm/python" | sed 's/^/   /'
python3 tools/data/lcm_log.py "$D/pool.lcm" status --types "$B/lcm/python" | sed 's/^/   last SONAR_STATUS (the firmware'"'"'s): /'
echo "== 5. the co-processor's SONAR_DETECTIONS against the truth (within 1 m)"
python3 tools/data/lcm_log.py "$D/pool.lcm" detections --types "$B/lcm/python" > "$D/pool.detections.jsonl"
python3 tools/eval/score.py "$D/pool.truth.json" "$D/pool.detections.jsonl" --verbose || true
