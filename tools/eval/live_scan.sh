#!/bin/sh
# live_scan.sh -- one live run of a moving scene: sonar-feed at device pace on the wall clock (--scene-clock wall, --truth)
# -> sonard --scan MODE over TCP on 127.0.0.1 -> score_live.py (revisit, unvisited, MOTA, IDF1, ID switches, velocity).
# Usage: sh tools/eval/live_scan.sh BUILD_DIR OUTDIR SCENE MODE SECONDS PORT [sonard options...]
# Writes OUTDIR/SCENE-MODE.{truth,jsonl,err,feed.err,score.json}; prints score_live.py's line; exits as it does.
set -u
B=$1; O=$2; SC=$3; MODE=$4; SEC=$5; PORT=$6; shift 6
mkdir -p "$O"
# The moving scenes' sonard settings: 15 m, 600 samples, 4 gradians a step (2 in the sector scene).
case "$SC" in
    sector) SET="--range 15 --samples 600 --step 2 --sector 100:300"; STEP=2 ;;
    *) SET="--range 15 --samples 600 --step 4"; STEP=4 ;;
esac
"$B/sonar-feed" --listen "tcp:127.0.0.1:$PORT" --scene "$SC" --scene-clock wall --truth "$O/$SC-$MODE.truth" \
    --max-seconds $((SEC + 15)) 2> "$O/$SC-$MODE.feed.err" &
fp=$!
sleep 0.3 # sonard retries a refused connect anyway
# shellcheck disable=SC2086
timeout $((SEC + 10)) "$B/sonard" --sonar "tcp:127.0.0.1:$PORT" $SET --min-points 8 --json --no-lcm --scan "$MODE" "$@" \
    > "$O/$SC-$MODE.jsonl" 2> "$O/$SC-$MODE.err" &
sp=$!
sleep "$SEC"
kill -TERM "$sp" 2>/dev/null
wait "$sp" 2>/dev/null
wait "$fp" 2>/dev/null
# STALLS (tests/stallwatch.py's file, when set): the machine's stalls, taken out of the unvisited stretches.
ST=""; [ -n "${STALLS:-}" ] && ST="--stalls $STALLS"
# shellcheck disable=SC2086
python3 tools/eval/score_live.py "$O/$SC-$MODE.truth" "$O/$SC-$MODE.jsonl" --step "$STEP" $ST --json > "$O/$SC-$MODE.score.json"
# shellcheck disable=SC2086
python3 tools/eval/score_live.py "$O/$SC-$MODE.truth" "$O/$SC-$MODE.jsonl" --step "$STEP" $ST --label "$SC $MODE: "
