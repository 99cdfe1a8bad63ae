#!/bin/sh
# fresh_check.sh -- `make fresh-check`: the README's commands as a new user runs them, in a minimal Debian bookworm made
# with debootstrap (cached in build/fresh/base-KEY.tar, made again when this recipe changes) with a clean clone of HEAD
# copied in and nothing else installed: apt-get install make (the README's first line), make demo, the first of make
# test's targets, make (all), make ARCH=armhf and ARCH=arm64 with a replay under qemu-user byte-equal to amd64's, make
# deb with the package installed (apt-get install ./...deb) and one replay by /usr/bin/sonard, make ros2 and make
# ros2-test (pip's downloads kept in build/fresh/pip). Every README command
# line that starts with make is run here or listed below as not run, with the reason. Downloaded packages are kept in
# build/fresh/apt (as a mirror would be); everything is installed afresh each time. Needs root (debootstrap, chroot).
# Usage: sh tools/build/fresh_check.sh [BUILD]. Ends with "fresh-check: N passed, N failed" and the time it took.
set -u
B=${1:-build}
F=$B/fresh
SUITE=bookworm
. "$(dirname "$0")/../../tests/lib.sh"
started=$(date +%s)
T=$(mktemp -d /tmp/sonard-fresh.XXXXXX)
if [ "$(id -u)" -ne 0 ]; then
    echo "fresh-check: SKIPPED: debootstrap and chroot need root (CI runs as root)"
    echo "fresh-check: 0 passed, 0 failed, 1 skipped"
    exit 0
fi
sh tools/build/deps.sh debootstrap qemu-user-static binfmt-support git
APT_WHO=fresh-check sudo=
. tools/build/apt.sh
# README command lines that start with make and are not run here, and why (the check fails on any other).
NOT_RUN="make blueos|images for three platforms with buildah (root, a container store, binfmt): .ci/run runs it on the CI machine right after this check
make test|its first targets run here (deps unit docs-check); the whole of it is .ci/run's own first step"
mkdir -p "$F/apt"
RECIPE="debootstrap --variant=minbase $SUITE"
key=$(echo "$RECIPE" | cksum | cut -d' ' -f1)
base=$F/base-$SUITE-$key.tar
cold=0
if [ ! -e "$base" ]; then
    cold=1
    rm -rf "$F/base" "$F"/base-*.tar
    echo "fresh-check: $RECIPE (cached as $base)"
    boot() { rm -rf "$F/base"; $RECIPE "$F/base" > "$F/debootstrap.log" 2>&1; }
    retry_once "$RECIPE" boot || { tail -5 "$F/debootstrap.log"; exit 1; }
    rm -rf "$F"/base/var/cache/apt/archives/*.deb "$F"/base/var/lib/apt/lists/*
    tar -C "$F/base" -cf "$base" . && rm -rf "$F/base"
fi
R=$F/root
umount_all() {
    for m in root/.cache/pip var/cache/apt/archives dev/pts dev sys proc; do
        mountpoint -q "$R/$m" 2> /dev/null && umount -l "$R/$m"
    done
    return 0
}
umount_all
rm -rf "$R"
mkdir -p "$R"
tar -C "$R" -xf "$base"
trap 'umount_all; rm -rf "$T"' EXIT
mount -t proc proc "$R/proc"
mount --rbind /sys "$R/sys"
mount --rbind /dev "$R/dev"
mount --bind "$F/apt" "$R/var/cache/apt/archives"
mkdir -p "$F/pip" "$R/root/.cache/pip"
mount --bind "$F/pip" "$R/root/.cache/pip"
cp /etc/resolv.conf "$R/etc/resolv.conf" 2> /dev/null || true
# The network's trust, which is the machine's and not a package's: a proxy's CA (kept when ca-certificates is
# installed and rebuilds the bundle) and pip's settings, as any machine on this network has them.
mkdir -p "$R/etc/ssl/certs" "$R/usr/local/share/ca-certificates"
cp /etc/ssl/certs/ca-certificates.crt "$R/etc/ssl/certs/" 2> /dev/null || true
cp /usr/local/share/ca-certificates/* "$R/usr/local/share/ca-certificates/" 2> /dev/null || true
cp /etc/pip.conf "$R/etc/pip.conf" 2> /dev/null || true
NET_ENV=""
for v in SSL_CERT_FILE PIP_CERT REQUESTS_CA_BUNDLE CURL_CA_BUNDLE GIT_SSL_CAINFO http_proxy https_proxy no_proxy \
         HTTP_PROXY HTTPS_PROXY NO_PROXY; do
    eval "x=\${$v:-}"
    case $v in *_proxy | *_PROXY) ;; *) [ -n "$x" ] && x=/etc/ssl/certs/ca-certificates.crt ;; esac
    [ -n "$x" ] && NET_ENV="$NET_ENV $v=$x"
done
printf 'Binary::apt::APT::Keep-Downloaded-Packages "true";\n' > "$R/etc/apt/apt.conf.d/keep-cache"
# The sources a standard install has (debootstrap writes only the release's own), and one more: a mirror in mid-sync,
# whose indexes' sizes do not match its Release file (as deb.debian.org's armhf security index once did), for every
# architecture the build fetches. apt-get update fails on it every time; nothing may fail because of it.
m=$(sed -n 's/^deb \([^ ]*\) .*/\1/p' "$R/etc/apt/sources.list" | head -1)
{ echo "deb ${m:-http://deb.debian.org/debian} $SUITE main"
  echo "deb ${m:-http://deb.debian.org/debian} $SUITE-updates main"
  echo "deb http://deb.debian.org/debian-security $SUITE-security main"
  echo "deb [trusted=yes] file:/srv/mid-sync $SUITE main"; } > "$R/etc/apt/sources.list"
for a in amd64 armhf arm64; do
    mkdir -p "$R/srv/mid-sync/dists/$SUITE/main/binary-$a"
    printf 'Package: sonard-mid-sync\nVersion: 1\nArchitecture: %s\n\n' $a > "$R/srv/mid-sync/dists/$SUITE/main/binary-$a/Packages"
done
{ printf 'Origin: sonard fresh-check\nLabel: a mirror in mid-sync\nSuite: %s\nCodename: %s\nDate: %s\n' $SUITE $SUITE "$(date -Ru)"
  printf 'Architectures: amd64 armhf arm64\nComponents: main\nSHA256:\n'
  for a in amd64 armhf arm64; do
      f=$R/srv/mid-sync/dists/$SUITE/main/binary-$a/Packages
      printf ' %s %d main/binary-%s/Packages\n' "$(sha256sum "$f" | cut -d' ' -f1)" $(( $(wc -c < "$f") + 352 )) $a
  done; } > "$R/srv/mid-sync/dists/$SUITE/Release"
# A clean clone of HEAD, and ../shared beside it when there is one (the real recordings; tests skip without).
git clone -q . "$R/root/sonard"
[ -d ../shared ] && cp -r ../shared "$R/root/shared"
# shellcheck disable=SC2086 # NET_ENV: NAME=VALUE words without spaces
inside() { chroot "$R" /usr/bin/env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 $NET_ENV sh -c "cd /root/sonard && $1"; }
# 1. The README's first lines, as a new user types them on a fresh machine.
t0=$(date +%s)
inside "apt-get update -qq; apt-get install -y -qq make > /dev/null" > "$F/make.log" 2>&1
check "apt-get install make on the fresh system (README: the one thing make demo cannot install itself)" \
    sh -c "chroot '$R' sh -c 'command -v make' > /dev/null || { tail -5 '$F/make.log'; exit 1; }"
inside "make demo" > "$F/demo.log" 2>&1; rc=$?
t1=$(date +%s)
check "make demo on the fresh system: its installs, its build, the live run, the pool's objects found ($((t1 - t0)) s)" \
    sh -c "test $rc -eq 0 && grep -q 'F1 1.000' '$F/demo.log' || { tail -15 '$F/demo.log'; exit 1; }"
check "a mirror in mid-sync: make demo's apt-get update failure said, naming the index, and nothing failed for it" \
    sh -c "grep 'package index not updated: .*mid-sync/dists/$SUITE/main/binary-amd64' '$F/demo.log' | head -1 | grep . ||
           { grep -i 'apt\|index' '$F/demo.log' | head -5; exit 1; }"
inside "make deps unit docs-check" > "$F/test.log" 2>&1; rc=$?
t2=$(date +%s)
check "make test's first targets (deps unit docs-check) on the fresh system ($((t2 - t1)) s)" \
    sh -c "test $rc -eq 0 || { tail -15 '$F/test.log'; exit 1; }"
inside "make" > "$F/all.log" 2>&1; rc=$?
check "make (all) on the fresh system" sh -c "test $rc -eq 0 || { tail -5 '$F/all.log'; exit 1; }"
# 2. The Raspberry Pi builds: cross-built, then a replay under qemu-user equal to the amd64 build's.
inside "build/sonar-sim --scene pool --sweeps 3 --out /tmp/pool.csv --truth /tmp/pool.json > /dev/null &&
        build/sonard --replay /tmp/pool.csv --json --quiet --log-level warn > /tmp/amd64.jsonl" > "$F/replay.log" 2>&1
for a in armhf arm64; do
    q=qemu-arm-static; [ $a = arm64 ] && q=qemu-aarch64-static
    inside "make ARCH=$a" > "$F/$a.log" 2>&1; rc=$?
    t3=$(date +%s)
    check "make ARCH=$a on the fresh system, its sysroot and cross compiler installed by it ($((t3 - t2)) s)" \
        sh -c "test $rc -eq 0 || { grep -m3 -i error '$F/$a.log'; tail -5 '$F/$a.log'; exit 1; }"
    # apt need not name every index of a source it could not fetch (one run named armhf's and amd64's, not arm64's,
    # though all three were broken): any of the mid-sync source's, named, is the mirror said.
    check "... the mirror in mid-sync said by name on the way (an index of it), and nothing failed for it" \
        sh -c "grep -q 'package index not updated: .*mid-sync/dists/$SUITE/main/binary-' '$F/$a.log'"
    inside "$q -L build-$a/sysroot build-$a/sonard --replay /tmp/pool.csv --json --quiet --log-level warn > /tmp/$a.jsonl &&
            cmp /tmp/amd64.jsonl /tmp/$a.jsonl" > "$F/$a.replay.log" 2>&1; rc=$?
    check "... its sonard under $q replays the pool byte-equal to amd64's" \
        sh -c "test $rc -eq 0 || { tail -5 '$F/$a.replay.log'; exit 1; }"
    t2=$t3
done
# 3. The package: built, installed with its dependencies, one replay by the installed binary.
inside "make deb && apt-get install -y -qq ./build/sonard_*_amd64.deb > /dev/null &&
        /usr/bin/sonard --replay /tmp/pool.csv --json --quiet --log-level warn > /tmp/installed.jsonl &&
        cmp /tmp/amd64.jsonl /tmp/installed.jsonl" > "$F/deb.log" 2>&1; rc=$?
t4=$(date +%s)
check "make deb on the fresh system, apt-get install of the package, a replay by /usr/bin/sonard equal to the build's ($((t4 - t2)) s)" \
    sh -c "test $rc -eq 0 || { tail -8 '$F/deb.log'; exit 1; }"
# 4. ROS 2: make ros2 (its venv from the pinned wheels; pip's downloads kept in build/fresh/pip as apt's are), then
# make ros2-test, whole: the bridge against sonard in a network namespace, and a bag from lcm2mcap --ros2.
inside "make ros2 && make ros2-test" > "$F/ros2.log" 2>&1; rc=$?
t5=$(date +%s)
check "make ros2 and make ros2-test on the fresh system, every check run and passed ($((t5 - t4)) s)" \
    sh -c "test $rc -eq 0 && grep -qE '^ros2: [1-9][0-9]* passed, 0 failed' '$F/ros2.log' || { grep -E 'FAIL|SKIP|rror' '$F/ros2.log' | head -8; tail -5 '$F/ros2.log'; exit 1; }"
# 5. Every README command line that starts with make: run above, or listed as not run with its reason.
RUN="make demo|make|make ARCH=armhf|make ARCH=arm64|make deb|make deps unit docs-check|make ros2|make ros2-test"
awk '/^```/ { f = !f; next } f && /^make( |$)/ { sub(/[ \t]*#.*/, ""); print }' README.md | sort -u > "$F/readme.make"
missing=""
while IFS= read -r cmd; do
    if printf '%s\n' "$RUN" | tr '|' '\n' | grep -qxF "$cmd"; then
        echo "    run here: $cmd"
    elif reason=$(printf '%s\n' "$NOT_RUN" | grep -F "$cmd|" | cut -d'|' -f2-) && [ -n "$reason" ]; then
        echo "    not run here: $cmd: $reason"
    else
        missing="$missing [$cmd]"
    fi
done < "$F/readme.make"
check "every README command line that starts with make is run here or listed as not run with a reason ($(wc -l < "$F/readme.make") lines)" \
    sh -c "test -z '$missing' || { echo 'not accounted for:$missing'; exit 1; }"
umount_all
rm -rf "$T"
trap - EXIT
echo "fresh-check: $(( $(date +%s) - started )) s ($([ $cold -eq 1 ] && echo "cold: the base made" || echo "warm: the base from $base"))"
echo "fresh-check: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
