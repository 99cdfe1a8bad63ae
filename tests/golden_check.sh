#!/bin/sh
# golden_check.sh -- every scene's and recording's replay (tests/golden.sh) against the hashes in tests/golden.sha256.
# Usage: sh tests/golden_check.sh BUILD_DIR [--update]. A change that is meant to change the output
# rewrites the file (make golden-update) and says why in its commit; the AquaScan lines are checked
# only when ../shared is present (the hashes are of our output, not of the data).
set -eu
B=${1:-build}; MODE=${2:-check}
G=tests/golden.sha256
T=$(mktemp -d /tmp/sonard-golden.XXXXXX)
trap 'rm -rf "$T"' EXIT
sh tests/golden.sh "$B" "$T/out" > "$T/log"
grep "skipped" "$T/log" || true
(cd "$T/out" && sha256sum -- * | sort -k 2) > "$T/now"
if [ "$MODE" = "--update" ]; then
    if [ -f "$G" ]; then
        # keep the lines of outputs this machine could not make (no ../shared here)
        awk 'NR == FNR { have[$2] = 1; next } !($2 in have)' "$T/now" "$G" | cat - "$T/now" | sort -k 2 > "$T/new"
    else
        cp "$T/now" "$T/new"
    fi
    cp "$T/new" "$G"
    echo "golden: $G rewritten ($(wc -l < "$G") outputs)"
    exit 0
fi
fail=0; n=0
while read -r sum name; do
    want=$(awk -v f="$name" '$2 == f { print $1 }' "$G")
    n=$((n + 1))
    if [ -z "$want" ]; then
        echo "golden: $name has no hash in $G (make golden-update adds it)"; fail=1
    elif [ "$want" != "$sum" ]; then
        echo "golden: $name differs from $G: the replay's output changed (make golden-update if that is meant)"; fail=1
    fi
done < "$T/now"
missing=$(awk 'NR == FNR { have[$2] = 1; next } !($2 in have) { print $2 }' "$T/now" "$G" | grep -v '^sonar' || true)
if [ -n "$missing" ]; then
    echo "golden: not produced: $missing"; fail=1
fi
[ $fail -eq 0 ] && echo "golden: $n replays byte-identical to $G"
exit $fail
