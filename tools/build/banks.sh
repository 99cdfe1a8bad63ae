#!/bin/sh
# banks.sh -- each memory bank's use and headroom in a linked firmware image: the MEMORY regions of its linker script against the sections placed in them (arm-none-eabi-size -A); the stack is a reservation, its measured use is on SONAR_STATUS (stack_used).
# Usage: sh tools/build/banks.sh IMAGE.elf SCRIPT.ld
set -eu
ELF=$1; LD=$2
${ARM_SIZE:-arm-none-eabi-size} -A -d "$ELF" > "${ELF%.elf}.sections"
awk -v ld="$LD" '
    function hex(s,    i, c, v) { v = 0; s = tolower(s); sub(/^0x/, "", s)
        for (i = 1; i <= length(s); i++) { c = index("0123456789abcdef", substr(s, i, 1)) - 1; v = v * 16 + c }
        return v }
    FNR == NR {
        # MEMORY lines: NAME (attrs) : ORIGIN = 0x..., LENGTH = nK|nM
        if ($0 ~ /ORIGIN *=/ && $0 ~ /LENGTH *=/) {
            name = $1; o = $0; sub(/.*ORIGIN *= */, "", o); sub(/,.*/, "", o)
            l = $0; sub(/.*LENGTH *= */, "", l); mult = 1
            if (l ~ /K$/) { mult = 1024; sub(/K$/, "", l) } else if (l ~ /M$/) { mult = 1048576; sub(/M$/, "", l) }
            org[name] = hex(o); len[name] = l * mult; order[++n] = name
        }
        next
    }
    $2 ~ /^[0-9]+$/ && $3 ~ /^[0-9]+$/ {
        size = $2 + 0; addr = $3 + 0
        # not loaded: debug information, comments, attributes
        if (size == 0 || $1 ~ /^\.(debug|comment|ARM\.attributes)/) next
        # .data also takes its initial values in flash, copied at reset
        if ($1 == ".data") used["FLASH"] += size
        for (i = 1; i <= n; i++) {
            r = order[i]
            if (addr >= org[r] && addr < org[r] + len[r]) { used[r] += size; what[r] = what[r] " " $1 }
        }
    }
    END {
        for (i = 1; i <= n; i++) {
            r = order[i]
            printf "bank %-6s %8d of %8d B used, %8d B (%.1f KiB) spare:%s\n", r, used[r], len[r], len[r] - used[r], (len[r] - used[r]) / 1024, what[r]
        }
    }' "$LD" "${ELF%.elf}.sections"
