#!/bin/sh
# arm.sh -- `make test-arm`: sonard and its tests cross-built for a Raspberry Pi (armhf: BlueOS on a Pi 4; arm64: a
# Pi 5) with Debian's cross compilers, run under qemu-user through binfmt: every unit test passes, every golden
# replay is byte-identical to this machine's (tests/golden.sha256), and each architecture's package holds programs
# that replay as this machine's do. Needs this machine's build (make all) for the reference. Ends with "N passed, N failed".
set -u
T=$(mktemp -d /tmp/sonard-arm.XXXXXX)
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
sudo=; [ "$(id -u)" -eq 0 ] || sudo=sudo
# binfmt: the kernel hands ARM programs to qemu-user (the qemu-user-static and binfmt-support packages).
if [ ! -e /proc/sys/fs/binfmt_misc/register ]; then
    $sudo mount -t binfmt_misc binfmt_misc /proc/sys/fs/binfmt_misc 2> /dev/null || true
fi
for a in armhf arm64; do
    q=qemu-arm; [ $a = arm64 ] && q=qemu-aarch64
    B=build-$a
    if ! make --no-print-directory ARCH=$a -j2 all > "$T/$a.build" 2>&1; then
        ko "$a: cross build (make ARCH=$a)"; tail -5 "$T/$a.build" | sed 's/^/    /'; continue
    fi
    ok "$a: make ARCH=$a builds sonard, sonar-sim, sonar-feed, pvbin2csv and sonar-wallfit into $B"
    [ -e /proc/sys/fs/binfmt_misc/$q ] || $sudo update-binfmts --enable $q > /dev/null 2>&1 || true
    export QEMU_LD_PREFIX="$PWD/$B/sysroot"
    if ! "$B/sonard" --version > "$T/$a.ver" 2>&1; then
        ko "$a: $B/sonard does not run here: binfmt has no $q (apt-get install qemu-user-static binfmt-support; mount binfmt_misc)"
        continue
    fi
    check "$a: the unit tests pass under $q" make --no-print-directory ARCH=$a -j2 unit
    check "$a: the golden replays are byte-identical to this machine's" sh tests/golden_check.sh "$B"
    # The package: built for the architecture, and its own programs (unpacked, the target's libraries beside them)
    # replay the pool to the same detections as this machine's build. Installing it in a chroot of the
    # architecture is not done here yet.
    if make --no-print-directory ARCH=$a deb > "$T/$a.deb" 2>&1; then
        d=$(ls "$B"/sonard_*_$a.deb)
        rm -rf "$T/root" && dpkg-deb -x "$d" "$T/root"
        build/sonar-sim --scene pool --sweeps 3 --out "$T/pool.csv" --truth "$T/pool.json" > /dev/null
        build/sonard --replay "$T/pool.csv" --json --quiet --log-level warn > "$T/host.jsonl"
        "$T/root/usr/bin/sonard" --replay "$T/pool.csv" --json --quiet --log-level warn > "$T/$a.jsonl" 2> "$T/$a.err"
        check "$a: make deb ARCH=$a: $(basename "$d") ($(du -k "$d" | cut -f1) KB), Architecture $a, its sonard replays the pool as this machine's does" \
            sh -c "test \"\$(dpkg-deb -f '$d' Architecture)\" = $a && cmp '$T/host.jsonl' '$T/$a.jsonl'"
    else
        ko "$a: make deb ARCH=$a"; tail -5 "$T/$a.deb" | sed 's/^/    /'
    fi
    unset QEMU_LD_PREFIX
done
echo "arm: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
