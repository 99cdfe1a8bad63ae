#!/bin/sh
# start.sh -- the BlueOS extension's entrypoint: the live view on 0.0.0.0:8360 and sonard, both as the sonard user.
# /config (BlueOS binds /usr/blueos/extensions/sonard there) keeps sonard.conf, copied from the image's on the first
# start; edit it there and restart the extension. sonard finds the Ping360 through BlueOS's ping service unless the
# file names another --sonar. Exits with sonard, so BlueOS (RestartPolicy unless-stopped) starts it again.
# A file /config/record-survey (its content the sweeps, 40 if none) records the site's survey first, with the
# configuration alone, once: it is taken away before the recording, so that a refused survey is said in the log and
# never retried in a loop.
set -eu
C=${SONARD_CONFIG_DIR:-/config}
mkdir -p "$C"
[ -f "$C/sonard.conf" ] || cp /usr/share/sonard/blueos/sonard.conf "$C/sonard.conf"
chown -R sonard:sonard "$C"
cd "$C"
runuser -u sonard -- sonar-view --listen "0.0.0.0:${SONARD_VIEW_PORT:-8360}" &
# The survey's file: the configuration's, else /config/site.survey (a configuration copied before surveys were);
# control (Cockpit's actions) on unless the configuration says (one copied before control was has no key).
sv=
grep -q '^[[:space:]]*survey[[:space:]]*=' "$C/sonard.conf" || sv="--survey $C/site.survey"
ctl=
grep -q '^[[:space:]]*control[[:space:]]*=' "$C/sonard.conf" || ctl="--control"
if [ -f "$C/record-survey" ]; then
    n=$(tr -cd 0-9 < "$C/record-survey")
    rm -f "$C/record-survey"
    # shellcheck disable=SC2086 # $sv is empty or an option and its path (no spaces: $C is the bound /config)
    runuser -u sonard -- sonard --config "$C/sonard.conf" $sv --quiet --survey "${n:-40}" ||
        echo "start.sh: no survey recorded (the reason is above); sonard runs on without a new one" >&2
fi
# shellcheck disable=SC2086
exec runuser -u sonard -- sonard --config "$C/sonard.conf" $sv $ctl --quiet "$@"
