#!/bin/sh
# crosscheck.sh -- Blue Robotics' bluerobotics-ping (PyPI, in .venv-brping) reads a sweep from sonar-feed over UDP.
set -u
B=${1:-build}
PY=${2:-.venv-brping/bin/python}
PORT=$(( 40000 + ($$ % 20000) ))
T=$(mktemp -d /tmp/sonard-xcheck.XXXXXX)
"$B/sonar-feed" --listen "udp:127.0.0.1:$PORT" --scene pool --pace fast --log "$T/feed.log" --max-seconds 60 2>/dev/null &
FEED=$!
trap 'kill $FEED 2>/dev/null; rm -rf "$T"' EXIT
sleep 0.2
if timeout 60 "$PY" tools/data/brping_check.py --port "$PORT" > "$T/out" 2>&1; then
    echo "[  PASS  ] $(tail -1 "$T/out")"
    echo "crosscheck: 1 passed, 0 failed"
else
    echo "[  FAIL  ] bluerobotics-ping against sonar-feed"; sed 's/^/    /' "$T/out"
    echo "crosscheck: 0 passed, 1 failed"
    exit 1
fi
