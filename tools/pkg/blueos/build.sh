#!/bin/sh
# build.sh -- `make blueos`: the BlueOS extension image for linux/arm/v7, linux/arm64/v8 and linux/amd64 from
# tools/pkg/blueos/Dockerfile with Debian's buildah (chroot isolation: this machine runs no container runtime, and
# qemu-user through binfmt runs the image's foreign RUN steps), each written as an OCI archive:
# build/blueos/sonard-blueos-{armv7,arm64,amd64}.tar. No registry is reachable here, so the Dockerfile's base,
# docker.io/library/debian:bookworm-slim, is made from Debian's archive (debootstrap --variant=minbase, slimmed as
# Debian's own slim images are: no docs, man pages or locales) and imported under that name before each build; on a
# machine that can pull, the same Dockerfile builds unchanged. Bases are kept in build/blueos/base-ARCH between runs.
# Usage: sh tools/pkg/blueos/build.sh [armv7 arm64 amd64]. Needs root (debootstrap, buildah's storage).
set -eu
O=build/blueos
BASE=docker.io/library/debian:bookworm-slim
SUITE=bookworm
mkdir -p "$O"
sh tools/build/deps.sh buildah podman debootstrap qemu-user-static binfmt-support
APT_WHO=blueos sudo=
. tools/build/apt.sh
[ -e /proc/sys/fs/binfmt_misc/register ] || mount -t binfmt_misc binfmt_misc /proc/sys/fs/binfmt_misc
for p in ${*:-armv7 arm64 amd64}; do
    case $p in
    armv7) deb=armhf; plat=linux/arm/v7; garch=arm; var=v7; q=qemu-arm ;;
    arm64) deb=arm64; plat=linux/arm64/v8; garch=arm64; var=v8; q=qemu-aarch64 ;;
    amd64) deb=amd64; plat=linux/amd64; garch=amd64; var=; q= ;;
    *) echo "blueos: $p: armv7, arm64 or amd64" >&2; exit 2 ;;
    esac
    [ -z "$q" ] || [ -e /proc/sys/fs/binfmt_misc/$q ] || update-binfmts --enable $q > /dev/null 2>&1 ||
        { echo "blueos: binfmt has no $q: apt-get install qemu-user-static binfmt-support" >&2; exit 1; }
    # The package of the architecture (this machine's build for amd64, the cross build otherwise).
    if [ "$deb" = "$(dpkg --print-architecture)" ]; then
        make --no-print-directory deb > "$O/deb-$p.log" 2>&1 || { tail -5 "$O/deb-$p.log"; exit 1; }
        d=$(ls build/sonard_*_"$deb".deb)
    else
        make --no-print-directory ARCH=$deb deb > "$O/deb-$p.log" 2>&1 || { tail -5 "$O/deb-$p.log"; exit 1; }
        d=$(ls build-$deb/sonard_*_"$deb".deb)
    fi
    # The base: Debian's minimal system, slimmed like Debian's slim images.
    b=$O/base-$p
    if [ ! -e "$b/.done" ]; then
        rm -rf "$b"
        boot() { rm -rf "$b"; debootstrap --arch=$deb --variant=minbase $SUITE "$b" > "$O/base-$p.log" 2>&1; }
        retry_once "debootstrap of the $p base" boot || { tail -5 "$O/base-$p.log"; exit 1; }
        cat > "$b/etc/dpkg/dpkg.cfg.d/slim" <<'EOC'
# as Debian's slim images: no documentation, manual pages or translations installed
path-exclude /usr/share/doc/*
path-include /usr/share/doc/*/copyright
path-exclude /usr/share/man/*
path-exclude /usr/share/groff/*
path-exclude /usr/share/info/*
path-exclude /usr/share/locale/*
path-exclude /usr/share/lintian/*
path-exclude /usr/share/linda/*
EOC
        find "$b/usr/share/doc" -mindepth 1 ! -name copyright ! -type d -delete 2> /dev/null || true
        find "$b/usr/share/doc" -mindepth 1 -type d -empty -delete 2> /dev/null || true
        rm -rf "$b"/usr/share/man/* "$b"/usr/share/info/* "$b"/usr/share/locale/* "$b"/usr/share/lintian/* \
            "$b"/var/cache/apt/*.bin "$b"/var/cache/apt/archives/*.deb "$b"/var/lib/apt/lists/* "$b"/var/log/* "$b"/tmp/*
        touch "$b/.done"
    fi
    podman rmi -f "$BASE" > /dev/null 2>&1 || true
    tar --exclude=./.done -C "$b" -c . |
        podman import --arch $garch ${var:+--variant $var} --os linux - "$BASE" > /dev/null
    # The context: the package, the entrypoint and the extension's configuration.
    c=$O/context-$p
    rm -rf "$c"
    mkdir -p "$c/debs"
    cp "$d" "$c/debs/"
    cp tools/pkg/blueos/Dockerfile tools/pkg/blueos/start.sh tools/pkg/blueos/blueos.conf "$c/"
    buildah build --isolation chroot --pull=never --platform $plat -t localhost/sonard-blueos:$p "$c" > "$O/build-$p.log" 2>&1 ||
        { tail -15 "$O/build-$p.log"; exit 1; }
    rm -f "$O/sonard-blueos-$p.tar"
    podman save -q --format oci-archive -o "$O/sonard-blueos-$p.tar" localhost/sonard-blueos:$p
    echo "blueos: $O/sonard-blueos-$p.tar ($plat, $(du -m "$O/sonard-blueos-$p.tar" | cut -f1) MB archive)"
done
podman rmi -f "$BASE" > /dev/null 2>&1 || true
