#!/bin/sh
# arm_sysroot.sh -- what a cross build for a Raspberry Pi needs (make ARCH=armhf|arm64): Debian's cross compiler and
# its C library headers, qemu-user, and the target's LCM, cmocka, glib and libc unpacked into DEST with dpkg -x (downloaded with apt-get
# download for ARCH; never installed over the host's, whose liblcm the armhf one would replace).
# Usage: sh tools/build/arm_sysroot.sh ARCH DEST
set -eu
A=$1; D=$2
case $A in
    armhf) triple=arm-linux-gnueabihf ;;
    arm64) triple=aarch64-linux-gnu ;;
    *) echo "arm_sysroot.sh: ARCH=$A: armhf or arm64" >&2; exit 2 ;;
esac
sudo=; [ "$(id -u)" -eq 0 ] || sudo=sudo
# The cross compiler's own C library headers (bits/wordsize.h ...) are only its Recommends, which deps.sh does not take.
sh "$(dirname "$0")/deps.sh" "gcc-$triple" "libc6-dev-$A-cross" qemu-user-static binfmt-support
APT_WHO=arm_sysroot
. "$(dirname "$0")/apt.sh"
pkgs="liblcm1:$A liblcm-dev:$A libglib2.0-0:$A libcmocka0:$A libcmocka-dev:$A libc6:$A libgcc-s1:$A libffi8:$A libmount1:$A
      libpcre2-8-0:$A libselinux1:$A zlib1g:$A libblkid1:$A"
if ! dpkg --print-foreign-architectures | grep -qx "$A"; then
    $sudo dpkg --add-architecture "$A"
    apt_update
fi
# shellcheck disable=SC2086
[ -n "$(apt_unavailable $pkgs)" ] && apt_update # the architecture was added by a run whose update failed
T=$(mktemp -d /tmp/sonard-sysroot.XXXXXX)
trap 'rm -rf "$T"' EXIT
# shellcheck disable=SC2086
download() { rm -f "$T"/*.deb; (cd "$T" && apt-get download -qq -o APT::Sandbox::User=root $pkgs); }
if ! retry_once "apt-get download of the $A packages" download; then
    # shellcheck disable=SC2086
    gone=$(apt_unavailable $pkgs)
    if [ -n "$gone" ]; then echo "arm_sysroot: error: no package source offers:$gone" >&2
    else echo "arm_sysroot: error: downloading the $A packages failed though every one is offered" >&2; fi
    exit 1
fi
rm -rf "$D"
mkdir -p "$D"
for f in "$T"/*.deb; do dpkg -x "$f" "$D"; done
# The stamp is this recipe's checksum: the Makefile makes the sysroot again when the recipe changes.
cksum < "$0" | cut -d' ' -f1 > "$D/.done"
echo "arm_sysroot: $D: $(ls "$T" | wc -l) packages for $A"
