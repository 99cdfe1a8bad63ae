#!/bin/sh
# vendor_view.sh -- installs the live view into DEST (sonar_view.py, lcm_udpm.py, the page, Cockpit's widgets, VERSION, and the pinned
# pure-Python websockets from tools/pkg/view-vendor.txt in DEST/vendor), for the .deb and the BlueOS image alike.
# Usage: sh tools/pkg/vendor_view.sh DEST CACHE_DIR. The wheel is downloaded once into CACHE_DIR, checked by its hash.
set -eu
D=$1
C=$2
V=$(sed -n 's/^#define SONARD_VERSION "\(.*\)"$/\1/p' src/host/version.h)
mkdir -p "$D/vendor" "$C"
if ! ls "$C"/websockets-*.whl > /dev/null 2>&1; then
    python3 -m pip download -q --no-deps --require-hashes --only-binary=:all: --platform any --python-version 3.11 \
        --implementation py --abi none -r tools/pkg/view-vendor.txt -d "$C" ||
        { echo "vendor_view: could not download the pinned websockets wheel (tools/pkg/view-vendor.txt)" >&2; exit 1; }
fi
install -m 0644 tools/view/sonar_view.py tools/view/lcm_udpm.py tools/view/index.html tools/view/view.js \
    tools/view/widget_fan.html tools/view/widget_status.html tools/view/widget_status.js tools/view/icon.svg "$D/"
chmod 0755 "$D/sonar_view.py"
echo "$V" > "$D/VERSION"
python3 -m zipfile -e "$C"/websockets-*.whl "$D/vendor"
rm -f "$D"/vendor/websockets/speedups.c "$D"/vendor/websockets/speedups.pyi
find "$D" -name '__pycache__' -prune -exec rm -rf {} +
find "$D/vendor" -type d -exec chmod 0755 {} + 
find "$D/vendor" -type f -exec chmod 0644 {} +
