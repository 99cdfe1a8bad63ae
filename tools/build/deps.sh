#!/bin/sh
# deps.sh -- installs the Debian packages sonard's build, tests and tools need, only those missing; idempotent. An index
# that cannot be fetched is a warning (tools/build/apt.sh); only a package that cannot be had fails it, by name.
set -eu
pkgs="make gcc g++ clang libclang-rt-14-dev pkg-config binutils libcmocka-dev libopencv-dev gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm python3 python3-venv liblcm-dev liblcm-bin"
[ "$#" -gt 0 ] && pkgs="$*"
missing=""
for p in $pkgs; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "deps: installing:$missing"
if [ "$(id -u)" -eq 0 ]; then sudo=""; elif command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
    echo "deps: not root and no sudo; install these by hand:$missing" >&2; exit 1
fi
APT_WHO=deps
. "$(dirname "$0")/apt.sh"
apt_update
# shellcheck disable=SC2086
apt_install $missing
