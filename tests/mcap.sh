#!/bin/sh
# mcap.sh -- tools/data/lcm2mcap: an LCM log of a replay turned into MCAP and read back with the mcap library (counts,
# fields and times against the log), the fan image and scene, a truncated and a corrupt log, an undecodable message,
# and live recording off a udpm bus inside a network namespace of its own. Usage: sh tests/mcap.sh BUILD_DIR.
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-mcap.XXXXXX)
PY=.venv-mcap/bin/python
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
L2M="$PY tools/data/lcm2mcap --types $B/lcm/python --lcm-types lcm_types"

"$B/sonar-sim" --scene moving --out "$T/mv.csv" --truth "$T/mv.json" > /dev/null 2>&1
"$B/sonard" --replay "$T/mv.csv" --min-points 8 --json --publish-filtered --lcm "file://$T/mv.lcm?mode=w" \
    > "$T/mv.jsonl" 2> "$T/mv.err"
$L2M "$T/mv.lcm" "$T/mv.mcap" > "$T/conv.out" 2>&1
rc=$?
cat "$T/conv.out"
check "lcm2mcap converts the replay's LCM log (exit 0)" test $rc -eq 0
check "read back with the mcap reader: every LCM channel's message count, fields and times match the log" \
    $PY - "$T/mv.lcm" "$T/mv.mcap" "$B/lcm/python" <<'PY'
import base64, json, sys
sys.path.insert(0, "tools/data"); sys.path.insert(0, sys.argv[3])
from lcm_log import events
from mcap.reader import make_reader
from sonar import beam_t, detections_t, tracks_t, status_t
lcm = {}
for t, ch, d in events(sys.argv[1]):
    lcm.setdefault(ch, []).append(d)
r = make_reader(open(sys.argv[2], "rb"))
mc = {}
for sc, ch, m in r.iter_messages():
    mc.setdefault(ch.topic, []).append((sc.name, m))
stats = r.get_summary().statistics
print({k: len(v) for k, v in sorted(lcm.items())})
print({k: len(v) for k, v in sorted(mc.items())})
for ch in lcm:
    assert len(mc.get(ch, [])) == len(lcm[ch]), (ch, len(mc.get(ch, [])), len(lcm[ch]))
assert stats.message_count == sum(len(v) for v in mc.values())
cls = {"SONAR_BEAM": beam_t, "SONAR_BEAM_FILTERED": beam_t, "SONAR_DETECTIONS": detections_t,
       "SONAR_TRACKS": tracks_t, "SONAR_STATUS": status_t}
for ch, c in cls.items():
    if ch not in lcm:
        continue  # a replay publishes no SONAR_STATUS
    for raw, (schema, m) in zip(lcm[ch], mc[ch]):
        a, j = c.decode(raw), json.loads(m.data)
        assert schema == "sonar." + c.__name__, schema
        assert m.log_time == a.utime * 1000, (ch, m.log_time, a.utime)  # the message's own time: a beam's is the beam's
        assert j["utime"] == a.utime
        if c is beam_t:
            assert base64.b64decode(j["samples"]) == bytes(a.samples) and j["angle"] == a.angle
            assert abs(j["range_m"] - a.range_m) < 1e-6
        if c is detections_t:
            assert j["sweep"] == a.sweep and len(j["detections"]) == a.count
            for x, y in zip(j["detections"], a.detections):
                assert abs(x["x_m"] - y.x_m) < 1e-6 and x["hull_x"] == list(y.hull_x) and x["points"] == y.points
        if c is tracks_t:
            assert [k["id"] for k in j["tracks"]] == [k.id for k in a.tracks]
            assert all(abs(k["vx_mps"] - q.vx_mps) < 1e-6 for k, q in zip(j["tracks"], a.tracks))
# the JSON sonard printed and the MCAP agree on the detections too
js = [json.loads(l) for l in open(sys.argv[2].replace(".mcap", ".jsonl"))]
assert [len(l["detections"]) for l in js] == [len(json.loads(m.data)["detections"]) for _, m in mc["SONAR_DETECTIONS"]]
print("fields and times match for", sum(len(lcm.get(c, [])) for c in cls), "messages")
PY
check "/sonar/fan: a mono8 foxglove.RawImage per sweep, echoes drawn; /sonar/scene: hulls and track IDs per sweep" \
    $PY - "$T/mv.mcap" <<'PY'
import base64, json, sys
from mcap.reader import make_reader
r = make_reader(open(sys.argv[1], "rb"))
fans, scenes, sweeps = [], [], 0
for sc, ch, m in r.iter_messages():
    if ch.topic == "/sonar/fan":
        assert sc.name == "foxglove.RawImage" and sc.encoding == "jsonschema" and ch.message_encoding == "json"
        fans.append(json.loads(m.data))
    elif ch.topic == "/sonar/scene":
        assert sc.name == "foxglove.SceneUpdate"
        scenes.append(json.loads(m.data))
    elif ch.topic == "SONAR_DETECTIONS":
        sweeps += 1
assert len(fans) == len(scenes) == sweeps, (len(fans), len(scenes), sweeps)
f = fans[-1]
px = base64.b64decode(f["data"])
assert f["encoding"] == "mono8" and len(px) == f["width"] * f["height"] == f["step"] * f["height"]
lit = sum(1 for v in px if v > 0)
assert lit > 0.1 * len(px) and max(px) > 100, (lit, max(px))
lines = sum(len(e["lines"]) for s in scenes for e in s["entities"])
ids = {e["id"] for s in scenes for e in s["entities"] if e["id"].startswith("track-")}
assert lines > 10 and len(ids) >= 3, (lines, ids)
print(len(fans), "fans,", lit, "lit pixels in the last;", lines, "hulls;", len(ids), "track IDs")
PY
# MCAP size per hour, from this scene's length
$PY - "$T/mv.lcm" "$T/mv.mcap" "$B/lcm/python" <<'PY'
import os, struct, sys
sys.path.insert(0, "tools/data"); sys.path.insert(0, sys.argv[3])
from lcm_log import events
from sonar import beam_t
t = [beam_t.decode(d).utime for u, ch, d in events(sys.argv[1]) if ch == "SONAR_BEAM"]
h = (t[-1] - t[0]) / 3.6e9
print("mcap: %.1f MB LCM log -> %.1f MB MCAP for %.1f min of beams (raw and filtered, 600 samples): %.0f MB an hour"
      % (os.path.getsize(sys.argv[1]) / 1e6, os.path.getsize(sys.argv[2]) / 1e6, h * 60, os.path.getsize(sys.argv[2]) / 1e6 / h))
PY

# A truncated log: the event cut in half is named with its byte offset, what came before is kept.
$PY - "$T/mv.lcm" "$T/cut.lcm" "$T/cut.want" <<'PY'
import struct, sys
d = open(sys.argv[1], "rb").read()
off, n = 0, 0
while off < len(d) // 2:  # find the event that spans the middle
    _, _, _, cl, dl = struct.unpack_from(">IqqII", d, off)
    off += 28 + cl + dl
    n += 1
open(sys.argv[2], "wb").write(d[:off + 40])
open(sys.argv[3], "w").write("%d %d" % (off, n))
PY
read cut_at cut_n < "$T/cut.want"
$L2M "$T/cut.lcm" "$T/cut.mcap" > "$T/cut.out" 2>&1
rc=$?
cat "$T/cut.out"
check "a truncated log: exit 1, 'truncated event at byte $cut_at', the $cut_n messages before it in the MCAP" sh -c "
test $rc -eq 1 && grep -q 'truncated event at byte $cut_at ' '$T/cut.out' && grep -q 'the $cut_n LCM messages before it' '$T/cut.out' &&
$PY -c \"
from mcap.reader import make_reader
r = make_reader(open('$T/cut.mcap', 'rb'))
n = sum(1 for _, c, _ in r.iter_messages() if not c.topic.startswith('/'))
assert n == $cut_n, n\""
# A corrupt sync word mid-file, and a message that does not decode.
$PY - "$T/mv.lcm" "$T/bad.lcm" "$T/bad.want" <<'PY'
import struct, sys
d = bytearray(open(sys.argv[1], "rb").read())
off, n, ev = 0, 0, []
while off < len(d):
    _, _, _, cl, dl = struct.unpack_from(">IqqII", d, off)
    ev.append((off, cl, dl, bytes(d[off + 28:off + 28 + cl])))
    off += 28 + cl + dl
# garble the payload of the first SONAR_DETECTIONS (keeping its length), then the sync word 3/4 of the way in
first = next(e for e in ev if e[3] == b"SONAR_DETECTIONS")
d[first[0] + 28 + first[1]:first[0] + 28 + first[1] + first[2]] = b"\xff" * first[2]
k = len(ev) * 3 // 4
d[ev[k][0]:ev[k][0] + 4] = b"XXXX"
open(sys.argv[2], "wb").write(bytes(d))
open(sys.argv[3], "w").write("%d" % ev[k][0])
PY
read bad_at < "$T/bad.want"
$L2M "$T/bad.lcm" "$T/bad.mcap" > "$T/bad.out" 2>&1
rc=$?
cat "$T/bad.out"
check "a corrupt log: the undecodable SONAR_DETECTIONS named and skipped, the bad sync word named at byte $bad_at, exit 1" sh -c "
test $rc -eq 1 && grep -q 'SONAR_DETECTIONS: message at log time .* does not decode as sonar.detections_t' '$T/bad.out' &&
grep -q 'bad sync word 0x58585858 at byte $bad_at' '$T/bad.out' && grep -q 'SONAR_DETECTIONS (undecodable) 1' '$T/bad.out'"

# What only a live sonard publishes, with each status: SONAR_STATUS, the clutter map (SONAR_CLUTTER) and, with a survey
# in use, the survey's structure (SONAR_SURVEY). A survey recorded off sonar-feed (TCP, 127.0.0.1) at full speed, then
# loaded by a second run at 20x the device's pace, logged to a file for 2.5 s.
port=$((32000 + $$ % 20000))
"$B/sonar-feed" --listen tcp:127.0.0.1:$port --scene pool --pace fast --max-seconds 60 > /dev/null 2>&1 &
fpid=$!
sleep 0.3
timeout -s TERM 30 "$B/sonard" --sonar tcp:127.0.0.1:$port --survey 40 --survey "$T/st.sv" --quiet --log-level warn \
    --no-lcm > /dev/null 2> "$T/st.err"
kill $fpid 2> /dev/null; wait $fpid 2> /dev/null
"$B/sonar-feed" --listen tcp:127.0.0.1:$port --scene pool --pace x20 --max-seconds 60 > /dev/null 2>&1 &
fpid=$!
sleep 0.3
timeout -s TERM 2.5 "$B/sonard" --sonar tcp:127.0.0.1:$port --survey "$T/st.sv" --quiet --log-level warn \
    --lcm "file://$T/st.lcm?mode=w" > /dev/null 2>> "$T/st.err"
kill $fpid 2> /dev/null; wait $fpid 2> /dev/null
$L2M "$T/st.lcm" "$T/st.mcap" > "$T/st.out" 2>&1
rc=$?
check "a live run's status channels: SONAR_STATUS, SONAR_CLUTTER and SONAR_SURVEY in the MCAP, each message's fields" \
    sh -c "test $rc -eq 0 && $PY - '$T/st.lcm' '$T/st.mcap' '$B/lcm/python'" <<'PY'
import json, sys
sys.path.insert(0, "tools/data"); sys.path.insert(0, sys.argv[3])
from lcm_log import events
from mcap.reader import make_reader
from sonar import clutter_t, survey_t, status_t
lcm = {}
for t, ch, d in events(sys.argv[1]):
    lcm.setdefault(ch, []).append(d)
mc = {}
for sc, ch, m in make_reader(open(sys.argv[2], "rb")).iter_messages():
    mc.setdefault(ch.topic, []).append((sc.name, json.loads(m.data)))
for ch, c in (("SONAR_STATUS", status_t), ("SONAR_CLUTTER", clutter_t), ("SONAR_SURVEY", survey_t)):
    assert lcm.get(ch), (ch, sorted(lcm))
    assert len(mc.get(ch, [])) == len(lcm[ch]), (ch, len(mc.get(ch, [])), len(lcm[ch]))
    for raw, (schema, j) in zip(lcm[ch], mc[ch]):
        a = c.decode(raw)
        assert schema == "sonar." + c.__name__ and j["utime"] == a.utime, (schema, ch)
        if c is clutter_t:
            assert j["cells"] == a.bands * a.sectors == len(j["density"]) and j["looks"] == a.looks
            assert all(abs(x - y) < 1e-6 for x, y in zip(j["density"], a.density))
        if c is survey_t:
            assert j["state"] == a.state and j["sweeps"] == a.sweeps == 40 and len(j["places"]) == a.count
print({ch: len(v) for ch, v in sorted(lcm.items()) if ch != "SONAR_BEAM"}, "converted, fields equal")
PY
sed 's/^/    /' "$T/out"

# Live: a replay publishing on udpm inside a network namespace, recorded as it goes (the recorder asks for a 4 MiB
# receive buffer: at 40x the beams come in bursts, and the default one lost 11 of 2400 once in CI). The recording
# ends half a second after the replay does (SIGINT), not at a fixed time: a paused machine stretches the replay.
if unshare -rn true 2> /dev/null; then
    cat > "$T/live.sh" <<EOF
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 3
$L2M --live 'udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304' "$T/live.mcap" --seconds 60 > "$T/live.out" 2>&1 & P=\$!
sleep 1
"$B/sonard" --replay "$T/mv.csv" --min-points 8 --json --quiet --log-level warn --replay-speed 40 --lcm 'udpm://239.255.76.67:7667?ttl=0' > "$T/live.jsonl"
sleep 0.5
kill -INT \$P
wait \$P
echo \$? > "$T/live.rc"
EOF
    unshare -rn sh "$T/live.sh"
    cat "$T/live.out"
    check "--live: a replay at 40x on a udpm bus recorded to MCAP: every sweep's detections, every beam" sh -c "
test \"\$(cat '$T/live.rc')\" = 0 && $PY -c \"
import json
from mcap.reader import make_reader
r = make_reader(open('$T/live.mcap', 'rb'))
c = r.get_summary().statistics.channel_message_counts
t = {ch.id: ch.topic for ch in r.get_summary().channels.values()}
n = {t[k]: v for k, v in c.items()}
sweeps = len(open('$T/live.jsonl').read().splitlines())
assert n.get('SONAR_DETECTIONS') == sweeps and n.get('SONAR_BEAM') == 2400, (n, sweeps)
print(n)\""
else
    ko "--live: unshare -rn (a network namespace for a private LCM bus) is not allowed here"
fi

echo "mcap: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
