#!/bin/sh
# size.sh -- links tools/build/mcu/image.c with the core for Cortex-M and prints flash and static RAM per configuration.
set -eu
B=${1:-build}
CC=${ARM_CC:-arm-none-eabi-gcc}
SIZE=${ARM_SIZE:-arm-none-eabi-size}
M7="-mcpu=cortex-m7 -mthumb -mfpu=fpv5-d16 -mfloat-abi=hard"
M4F="-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard"
mkdir -p "$B/mcu"
status=0
printf '%-34s %10s %10s %12s %12s\n' "image (limits)" "flash B" "RAM B" "pipeline B" "background B"
for v in "m7 400x1200|$M7|" "m7 400x600|$M7|-DSONAR_MAX_SAMPLES=600" "m4f 200x600|$M4F|-DSONAR_MAX_ANGLES=200 -DSONAR_MAX_SAMPLES=600" "m4f 400x1200|$M4F|"; do
    name=${v%%|*}; rest=${v#*|}; cpu=${rest%%|*}; defs=${rest#*|}
    out="$B/mcu/$(echo "$name" | tr ' ' '-').elf"
    # shellcheck disable=SC2086
    $CC $cpu $defs -std=c99 -Os -Wall -Werror -ffunction-sections -fdata-sections -Iinclude \
        tools/build/mcu/image.c src/core/*.c --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections -lm -o "$out" \
        -Wl,-Map="$out.map"
    set -- $($SIZE "$out" | tail -1)
    flash=$(( $1 + $2 )); ram=$(( $2 + $3 ))
    pipe=$(grep -A1 -E '^ \.bss\.pipeline' "$out.map" | grep -oE '0x[0-9a-f]+ +0x[0-9a-f]+' | head -1 | awk '{print $2}')
    bg=$(grep -A1 -E '^ \.bss\.background' "$out.map" | grep -oE '0x[0-9a-f]+ +0x[0-9a-f]+' | head -1 | awk '{print $2}')
    printf '%-34s %10d %10d %12d %12d\n' "$name" "$flash" "$ram" "$((pipe))" "$((bg))"
    # The STM32H743 places the background in its 512 KiB AXI SRAM and the rest, with an 8 KiB stack, in its
    # 128 KiB DTCM (src/mcu/h743.ld; make firmware links it and prints each bank).
    bg=$((bg))
    if [ "$name" = "m7 400x1200" ] && { [ "$bg" -gt 524288 ] || [ $((ram - bg + 8192)) -gt 131072 ]; }; then
        echo "size: FAILED: the default build does not fit an STM32H743: background $bg B of the 524288 B AXI SRAM," \
             "the rest $((ram - bg)) B + an 8 KiB stack of the 131072 B DTCM"; status=1
    fi
done
echo "(flash = text + data; RAM = data + bss, without stack; the background is the one block a board places in its large bank."
echo " STM32H743: the background in the 524288 B AXI SRAM, the rest and the stack in the 131072 B DTCM.)"
exit $status
