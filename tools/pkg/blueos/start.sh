#!/bin/sh
# start.sh -- the BlueOS extension's entrypoint: the live view on 0.0.0.0:8360 and sonard, both as the sonard user.
# /config (BlueOS binds /usr/blueos/extensions/sonard there) keeps sonard.conf, copied from the image's on the first
# start; edit it there and restart the extension. sonard finds the Ping360 through BlueOS's ping service unless the
# file names another --sonar. Exits with sonard, so BlueOS (RestartPolicy unless-stopped) starts it again.
set -eu
C=${SONARD_CONFIG_DIR:-/config}
mkdir -p "$C"
[ -f "$C/sonard.conf" ] || cp /usr/share/sonard/blueos/sonard.conf "$C/sonard.conf"
chown -R sonard:sonard "$C"
cd "$C"
runuser -u sonard -- sonar-view --listen "0.0.0.0:${SONARD_VIEW_PORT:-8360}" &
exec runuser -u sonard -- sonard --config "$C/sonard.conf" --quiet "$@"
