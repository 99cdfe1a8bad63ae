#!/bin/sh
# arm.sh -- `make test-arm`: sonard and its tests cross-built for a Raspberry Pi (armhf: BlueOS on a Pi 4; arm64: a
# Pi 5) with Debian's cross compilers, run under qemu-user through binfmt: every unit test passes, every golden
# replay is byte-identical to this machine's (tests/golden.sha256), and each architecture's package installs in a
# debootstrapped Debian of that architecture and replays there as this machine's build does (make all, the reference).
# Ends with "N passed, N failed".
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
    ok "$a: make ARCH=$a builds sonard, sonar-sim, sonar-feed, sonar-pvbin2csv and sonar-wallfit into $B"
    [ -e /proc/sys/fs/binfmt_misc/$q ] || $sudo update-binfmts --enable $q > /dev/null 2>&1 || true
    export QEMU_LD_PREFIX="$PWD/$B/sysroot"
    if ! "$B/sonard" --version > "$T/$a.ver" 2>&1; then
        ko "$a: $B/sonard does not run here: binfmt has no $q (apt-get install qemu-user-static binfmt-support; mount binfmt_misc)"
        continue
    fi
    check "$a: the unit tests pass under $q" make --no-print-directory ARCH=$a -j2 unit
    check "$a: the golden replays are byte-identical to this machine's" sh tests/golden_check.sh "$B"
    unset QEMU_LD_PREFIX
    # The package, installed in a Debian of the architecture (debootstrap from the archive this machine uses, into
    # build-ARCH/chroot, kept between runs) and started there on a replay: the same detections as this machine's.
    if ! make --no-print-directory ARCH=$a deb > "$T/$a.deb" 2>&1; then
        ko "$a: make deb ARCH=$a"; tail -5 "$T/$a.deb" | sed 's/^/    /'; continue
    fi
    d=$(ls "$B"/sonard_*_$a.deb)
    C=$B/chroot
    if [ ! -e "$C/.done" ]; then
        sh tools/build/deps.sh debootstrap
        rm -rf "$C"
        . /etc/os-release
        if ! $sudo debootstrap --arch=$a --variant=minbase --include=liblcm1,python3 "$VERSION_CODENAME" "$C" > "$T/$a.dbs" 2>&1; then
            ko "$a: debootstrap of $VERSION_CODENAME for $a"; tail -5 "$T/$a.dbs" | sed 's/^/    /'; continue
        fi
        touch "$C/.done"
    fi
    cp "$d" "$C/tmp/sonard.deb"
    build/sonar-sim --scene pool --sweeps 3 --out "$C/tmp/pool.csv" --truth "$T/pool.json" > /dev/null
    build/sonard --replay "$C/tmp/pool.csv" --json --quiet --log-level warn > "$T/host.jsonl"
    check "$a: $(basename "$d") ($(du -k "$d" | cut -f1) KB, Architecture $(dpkg-deb -f "$d" Architecture)) installs in a chroot of $a (dpkg -i) and makes its user" \
        sh -c "$sudo chroot '$C' dpkg -i /tmp/sonard.deb && $sudo chroot '$C' id sonard"
    $sudo chroot "$C" sh -c "sonard --replay /tmp/pool.csv --json --quiet --log-level warn" > "$T/$a.jsonl" 2> "$T/$a.err"
    check "$a: the installed sonard, started in the chroot on a replay, finds what this machine's does" cmp "$T/host.jsonl" "$T/$a.jsonl"
    check "$a: the installed Python LCM types import with the chroot's python3" \
        $sudo chroot "$C" python3 -c "from sonar import detections_t; detections_t()"
    check "$a: dpkg -P removes it and its configuration" \
        sh -c "$sudo chroot '$C' dpkg -P sonard > /dev/null && test ! -e '$C/etc/sonard/sonard.conf' && test ! -e '$C/usr/bin/sonard'"
done
echo "arm: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
