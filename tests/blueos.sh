#!/bin/sh
# blueos.sh -- `make blueos-test`: sonard where BlueOS users run it. In a network namespace of its own (BlueOS's ports
# 9110 and 9092 free there, nothing leaves the machine): --sonar blueos against a simulated ping service (good, with a
# Ping1D on the bridge; then absent, slow, garbage, an error, no Ping360: said once, 3 asks, the fallback bridge).
# Then the images of `make blueos`: the labels of each as BlueOS reads them, and the arm/v7 image's file system
# (unpacked from its OCI archive; no container runtime runs here) chrooted under qemu-user: its sonard on a replay
# equal to this machine's, and its entrypoint with the simulator behind a simulated ping service, its view as
# BlueOS's helper finds it. Usage: sh tests/blueos.sh BUILD_DIR (root). Ends with "N passed, N failed".
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-blueos.XXXXXX)
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
O=build/blueos
if ! unshare -rn true 2> /dev/null; then
    ko "blueos: unshare -rn (a network namespace with BlueOS's ports free) is not allowed here"
    echo "blueos: $pass passed, $fail failed"
    exit 1
fi
"$B/sonar-sim" --scene pool --out "$T/pool.csv" --truth "$T/pool.json" --sweeps 7 > /dev/null 2>&1

# 1. --sonar blueos on this machine's build.
cat > "$T/host.sh" <<EOF
ip link set lo up || exit 3
python3 tests/fake_ping_service.py --port 9110 --mode good --seconds 60 > "$T/good.asks" & S=\$!
"$B/sonar-feed" --listen udp:127.0.0.1:9092 --scene pool --pace fast --ping1d 0.2 --max-seconds 60 2> "$T/good.feed" & F=\$!
sleep 0.5
timeout 60 "$B/sonard" --sonar blueos --range 12 --sweeps 7 --json --no-lcm > "$T/good.jsonl" 2> "$T/good.err"
echo \$? > "$T/good.rc"
kill \$S \$F; wait
for m in none garbage error slow absent; do
    S=
    if [ \$m != absent ]; then python3 tests/fake_ping_service.py --port 9110 --mode \$m --seconds 60 > "$T/\$m.asks" & S=\$!; fi
    "$B/sonar-feed" --listen udp:127.0.0.1:9092 --scene pool --pace fast --max-seconds 60 2> /dev/null & F=\$!
    sleep 0.5
    s0=\$(date +%s.%N)
    timeout 60 "$B/sonard" --sonar blueos --range 12 --step 4 --sweeps 1 --json --no-lcm > "$T/\$m.jsonl" 2> "$T/\$m.err"
    echo "\$? \$(awk "BEGIN { print \$(date +%s.%N) - \$s0 }")" > "$T/\$m.rc"
    kill \$S \$F 2> /dev/null; wait
done
EOF
unshare -rn sh "$T/host.sh"
check "--sonar blueos: the ping service names the Ping360's bridge (a Ping1D listed first), sonard drives it, 7 sweeps" \
    sh -c "test \"\$(cat '$T/good.rc')\" = 0 && grep -q 'the ping service at 127.0.0.1:9110 names the Ping360 at udp:127.0.0.1:9092' '$T/good.err' || { cat '$T/good.err'; exit 1; }"
check "--sonar blueos: the pool's objects found (F1 >= 0.95)" python3 tools/eval/score.py "$T/pool.json" "$T/good.jsonl" --min-f1 0.95
fr=$(sed -n 's/.* foreign \([0-9]*\) .*/\1/p' "$T/good.err")
sent=$(sed -n 's/.*ping1d frames \([0-9]*\).*/\1/p' "$T/good.feed")
check "a Ping1D on the same bridge: its frames ignored and counted (status foreign $fr, the bridge relayed $sent)" \
    sh -c "test -n '$fr' && test '$fr' -gt 0 && test '$fr' = '$sent'"
for m in none garbage error slow absent; do
    rc=$(cut -d' ' -f1 "$T/$m.rc"); secs=$(cut -d' ' -f2 "$T/$m.rc")
    asks=$(sed -n 's/^asks //p' "$T/$m.asks" 2> /dev/null); [ $m = absent ] && asks=3
    why=$(sed -n 's/.*in 3 tries (\(.*\)); using.*/\1/p' "$T/$m.err")
    check "ping service $m: said once ($why), asked $asks times, fell back to the first bridge, 1 sweep (exit $rc, ${secs%.*} s)" \
        sh -c "test '$rc' = 0 && test \"\$(grep -c 'named no Ping360' '$T/$m.err')\" = 1 && test '$asks' = 3 &&
               grep -q 'using udp:127.0.0.1:9092' '$T/$m.err' && test \"\$(wc -l < '$T/$m.jsonl')\" -ge 1 || { cat '$T/$m.err'; exit 1; }"
done

# 2. The images.
for p in armv7:linux/arm/v7 arm64:linux/arm64/v8 amd64:linux/amd64; do
    a=${p%%:*}
    if [ ! -f "$O/sonard-blueos-$a.tar" ]; then
        ko "$O/sonard-blueos-$a.tar is missing: make blueos"
        continue
    fi
    python3 tests/blueos_labels.py "$O/sonard-blueos-$a.tar" "${p#*:}" tools/pkg/blueos/metadata.json > "$T/labels.$a" 2>&1
    cat "$T/labels.$a"
    pass=$((pass + $(grep -c '^\[  PASS' "$T/labels.$a")))
    fail=$((fail + $(grep -c '^\[  FAIL' "$T/labels.$a")))
done
A=$O/sonard-blueos-armv7.tar
if [ -f "$A" ]; then
    R=$T/rootfs
    python3 tests/oci_unpack.py "$A" "$R"
    mb=$(du -m "$A" | cut -f1); fs=$(du -sm "$R" | cut -f1)
    check "the arm/v7 image: $mb MB as its OCI archive (compressed layers, what the vehicle downloads) <= 80 MB; $fs MB unpacked" test "$mb" -le 80
    [ -e /proc/sys/fs/binfmt_misc/qemu-arm ] || update-binfmts --enable qemu-arm > /dev/null 2>&1 || true
    cp "$T/pool.csv" "$R/tmp/pool.csv"
    "$B/sonard" --replay "$T/pool.csv" --json --quiet --log-level warn > "$T/host.jsonl"
    chroot "$R" sonard --replay /tmp/pool.csv --json --quiet --log-level warn > "$T/armv7.jsonl" 2> "$T/armv7.err"
    check "the arm/v7 image's sonard (qemu-arm) on a replay: the same output as this machine's ($(wc -l < "$T/host.jsonl") sweeps)" \
        sh -c "cmp '$T/host.jsonl' '$T/armv7.jsonl' || { head -5 '$T/armv7.err'; exit 1; }"
    # The entrypoint as BlueOS starts it: host network (here a namespace of its own), /config bound, the ping service
    # on 9110 naming the bridge on 9092 (the image's own sonar-feed, a Ping1D relayed beside it).
    mkdir -p "$T/config"
    cat > "$T/image.sh" <<EOF
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 3
for d in dev proc sys; do mount --rbind /\$d "$R/\$d" || exit 4; done
mount --bind "$T/config" "$R/config" || exit 4
python3 tests/fake_ping_service.py --port 9110 --mode good --seconds 480 > /dev/null & S=\$!
chroot "$R" sonar-feed --listen udp:127.0.0.1:9092 --scene pool --pace fast --ping1d 0.1 --max-seconds 240 2> "$T/img.feed" & F=\$!
timeout 240 chroot "$R" sh /usr/share/sonard/blueos/start.sh --range 12 --sweeps 7 --json > "$T/img.jsonl" 2> "$T/img.err" & E=\$!
for i in \$(seq 120); do python3 -c "import socket; socket.create_connection(('127.0.0.1', 8360), 1)" 2> /dev/null && break; sleep 0.5; done
python3 tests/blueos_view_check.py --url http://127.0.0.1:8360/ --vendor .venv-view/lib/python3*/site-packages > "$T/img.view" 2>&1
python3 -c "
import json, time, urllib.request
for i in range(40):
    n = json.load(urllib.request.urlopen('http://127.0.0.1:8360/health', timeout=5))['counts']['beams']
    if n > 0:
        break
    time.sleep(0.5)
print(n)" > "$T/img.health" 2>&1
wait \$E; echo \$? > "$T/img.rc"
chroot "$R" sh -c 'stat -c %U /config/sonard.conf' > "$T/img.owner" 2>&1
kill \$F 2> /dev/null; wait \$F 2> /dev/null
# The survey as docs/blueos.md has it recorded: a file record-survey beside the configuration (range 12 m added
# there), the extension restarted with the site empty; the site then occupied, the survey loaded and in use. One
# feeder for both runs, empty until the survey's run stops the motor, then its people from sweep 0: no race between a
# feeder's end and the next's start for the run's first sweeps.
echo 'range = 12' >> "$T/config/sonard.conf"
echo 8 > "$T/config/record-survey"
chroot "$R" sonar-feed --listen udp:127.0.0.1:9092 --scene pool --arrive-at-motor-off --pace fast --max-seconds 240 2> /dev/null & F=\$!
timeout 240 chroot "$R" sh /usr/share/sonard/blueos/start.sh --sweeps 7 --json > "$T/sv.jsonl" 2> "$T/sv.err"
echo \$? > "$T/sv.rc"
kill \$S \$F 2> /dev/null
EOF
    mkdir -p "$R/config"
    # a pid namespace too: the view start.sh left behind ends with this script's shell, and nothing outside is signalled
    unshare -nmpf --mount-proc sh "$T/image.sh"
    cat "$T/img.view"
    pass=$((pass + $(grep -c '^\[  PASS' "$T/img.view")))
    fail=$((fail + $(grep -c '^\[  FAIL' "$T/img.view")))
    check "the arm/v7 entrypoint: sonard found the Ping360 through the ping service and ran its sweeps (exit 0)" \
        sh -c "test \"\$(cat '$T/img.rc')\" = 0 && grep -q 'names the Ping360 at udp:127.0.0.1:9092' '$T/img.err' || { tail -5 '$T/img.err'; exit 1; }"
    check "the arm/v7 entrypoint: the pool's objects found (F1 >= 0.95)" python3 tools/eval/score.py "$T/pool.json" "$T/img.jsonl" --min-f1 0.95
    check "the arm/v7 entrypoint: the view heard sonard over LCM ($(cat "$T/img.health") beams); /config/sonard.conf made, owned by $(cat "$T/img.owner")" \
        sh -c "test \"\$(cat '$T/img.health')\" -gt 0 && test -f '$T/config/sonard.conf' && test \"\$(cat '$T/img.owner')\" = sonard"
    check "the arm/v7 entrypoint with a file record-survey: the survey written to /config/site.survey, the file taken away" \
        sh -c "grep -q 'survey: written to /config/site.survey' '$T/sv.err' && test -f '$T/config/site.survey' &&
               test ! -e '$T/config/record-survey' || { tail -5 '$T/sv.err'; exit 1; }"
    check "... then loaded at start with no flag and in use: the occupied pool's objects found (F1 >= 0.95), exit 0" \
        sh -c "test \"\$(cat '$T/sv.rc')\" = 0 && grep -q 'survey: of .* in use' '$T/sv.err' &&
               python3 tools/eval/score.py '$T/pool.json' '$T/sv.jsonl' --min-f1 0.95 || { tail -5 '$T/sv.err'; exit 1; }"
fi
for a in armv7 arm64 amd64; do
    [ -f "$O/sonard-blueos-$a.tar" ] && echo "blueos: $O/sonard-blueos-$a.tar: $(du -m "$O/sonard-blueos-$a.tar" | cut -f1) MB"
done
echo "blueos: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
