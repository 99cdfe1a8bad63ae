#!/bin/sh
# fuzz_coverage.sh -- source coverage that a fuzz corpus reaches: each harness rebuilt with clang's
# -fprofile-instr-generate -fcoverage-mapping, run over its corpus directory, reported per file by llvm-cov.
# Usage: sh tools/build/fuzz_coverage.sh CORPUS_ROOT (with CORPUS_ROOT/ping360, csv, config, pvbin, mavlink, discover,
# posefile; a harness whose directory is absent is skipped); default tests/fuzz/corpus.
set -eu
C=${1:-tests/fuzz/corpus}
B=build-fuzzcov
make --no-print-directory BUILD=$B CC=clang OPT=-O0 SAN="-fprofile-instr-generate -fcoverage-mapping -fsanitize=fuzzer-no-link" \
    $B/fuzz/fuzz_ping360 $B/fuzz/fuzz_csv $B/fuzz/fuzz_config $B/fuzz/fuzz_pvbin $B/fuzz/fuzz_mavlink $B/fuzz/fuzz_discover \
    $B/fuzz/fuzz_posefile >/dev/null
for h in ping360:src/core/ping.c:src/core/ping360.c csv:src/host/csv.c config:src/host/optschema.c:src/host/options.c \
         pvbin:src/host/pvbin.c mavlink:src/host/mav_rx.c discover:src/host/discover.c posefile:src/host/posefile.c; do
    name=${h%%:*}; files=$(echo "${h#*:}" | tr ':' ' ')
    [ -d "$C/$name" ] || continue
    LLVM_PROFILE_FILE=$B/$name.profraw $B/fuzz/fuzz_$name -runs=0 "$C/$name" >/dev/null 2>&1
    llvm-profdata merge -sparse $B/$name.profraw -o $B/$name.profdata
    # shellcheck disable=SC2086
    llvm-cov report $B/fuzz/fuzz_$name -instr-profile=$B/$name.profdata $files | sed -n '3,$p' | grep -v '^-' |
        awk -v h="$name" '{ printf "%-8s %-26s lines %6s  branches %6s  functions %6s\n", h, $1, $10, $13, $7 }'
done
