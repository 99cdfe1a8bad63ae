#!/bin/sh
# deb.sh -- builds sonard_VERSION_ARCH.deb from a build directory: binaries, systemd units, the example config,
# the LCM types (sources, Python, the jar for lcm-spy), the docs; the sonard user is made by its postinst.
# Usage: sh tools/pkg/deb.sh BUILD_DIR [ARCH] (make deb, make deb ARCH=armhf|arm64: a cross build's programs, run
# under qemu-user for their --help, STRIP the target's strip). Needs dpkg-deb; dpkg-shlibdeps, when present and it
# knows the target's libraries, finds the library dependencies (else libc6, liblcm1).
set -eu
B=${1:-build}
A=${2:-$(dpkg --print-architecture)}
V=$(sed -n 's/^#define SONARD_VERSION "\(.*\)"$/\1/p' src/host/version.h)
R="$B/deb/root"
OUT="$B/sonard_${V}_${A}.deb"
rm -rf "$B/deb"
mkdir -p "$R/DEBIAN" "$R/usr/bin" "$R/lib/systemd/system" "$R/etc/sonard" "$R/usr/share/doc/sonard/examples" \
    "$R/usr/share/sonard/lcm_types" "$R/usr/share/java" "$R/usr/lib/python3/dist-packages"
install -m 0755 "$B/sonard" "$R/usr/bin/sonard"
install -m 0755 "$B/sonar-feed" "$R/usr/bin/sonar-feed"
install -m 0755 "$B/sonar-sim" "$R/usr/bin/sonar-sim"
install -m 0755 "$B/sonar-pvbin2csv" "$R/usr/bin/sonar-pvbin2csv"
install -m 0755 "$B/sonar-wallfit" "$R/usr/bin/sonar-wallfit"
${STRIP:-strip} --strip-unneeded --remove-section=.comment --remove-section=.note "$R"/usr/bin/sonar*
install -m 0644 tools/pkg/systemd/sonard.service tools/pkg/systemd/sonard@.service tools/pkg/systemd/sonar-view.service "$R/lib/systemd/system/"
# The live view (Python, no native code: the same for every architecture) and its launcher.
sh tools/pkg/vendor_view.sh "$R/usr/share/sonard/view" build/vendor
printf '#!/bin/sh\n# sonar-view -- the live view of sonard in a browser (see sonar-view --help)\nexec python3 /usr/share/sonard/view/sonar_view.py --types /usr/lib/python3/dist-packages "$@"\n' > "$R/usr/bin/sonar-view"
chmod 0755 "$R/usr/bin/sonar-view"
# The ROS 2 bridge (Python; ROS 2 itself is the user's: a sourced distribution's rclpy) beside the view, whose
# lcm_udpm.py it reads the bus with.
mkdir -p "$R/usr/share/sonard/ros2"
install -m 0644 tools/ros2/sonard_ros2.py tools/ros2/ros2_bag.py tools/data/fan.py "$R/usr/share/sonard/ros2/"
printf '#!/bin/sh\n# sonar-ros2 -- sonard on ROS 2 topics; source your ROS 2 distribution first (see sonar-ros2 --help)\nexec python3 /usr/share/sonard/ros2/sonard_ros2.py --types /usr/lib/python3/dist-packages "$@"\n' > "$R/usr/bin/sonar-ros2"
chmod 0755 "$R/usr/bin/sonar-ros2"
install -m 0644 docs/sonard.conf.example "$R/etc/sonard/sonard.conf"
install -m 0644 docs/sonard.conf.example "$R/usr/share/doc/sonard/examples/sonard.conf"
install -m 0644 lcm_types/*.lcm "$R/usr/share/sonard/lcm_types/"
install -m 0644 "$B/lcm/sonar_types.jar" "$R/usr/share/java/sonard.jar"
cp -r "$B/lcm/python/sonar" "$R/usr/lib/python3/dist-packages/sonar"
find "$R/usr/lib/python3" -name '__pycache__' -prune -exec rm -rf {} +
find "$R/usr/lib/python3" -type f -exec chmod 0644 {} +
install -m 0644 README.md "$R/usr/share/doc/sonard/README.md"
for f in docs/*.md docs/foxglove-ros2.json; do install -m 0644 "$f" "$R/usr/share/doc/sonard/"; done
mkdir -p "$R/usr/share/doc/sonard/presets"
for f in docs/presets/*.conf; do install -m 0644 "$f" "$R/usr/share/doc/sonard/presets/"; done
install -m 0644 tools/pkg/deb/copyright "$R/usr/share/doc/sonard/copyright"
printf 'sonard (%s) unstable; urgency=medium\n\n  * Built from %s.\n\n -- sonard developers <sonard@localhost>  %s\n' \
    "$V" "$(git describe --always --dirty 2> /dev/null || echo 'a source tree')" \
    "$(date -R -d @"${SOURCE_DATE_EPOCH:-$(git log -1 --format=%ct 2> /dev/null || date +%s)}")" |
    gzip -9n > "$R/usr/share/doc/sonard/changelog.gz" # a native package: changelog.gz
# Manual pages from each program's own --help (one source: the option tables), for man(1).
mkdir -p "$R/usr/share/man/man1"
for p in sonard:"Ping360 sonar to live object detections over LCM and MAVLink" \
         sonar-feed:"a simulated Ping360 on TCP, UDP or a pty" \
         sonar-sim:"simulated Ping360 recordings with their truth" \
         sonar-pvbin2csv:"Ping Viewer .bin logs to the study's CSV" \
         sonar-wallfit:"fits a recording's world grid to known walls" \
         sonar-view:"the live view of sonard in a browser" \
         sonar-ros2:"sonard on ROS 2 topics: scan, fan image, detections, tracks, diagnostics; odometry in"; do
    name=${p%%:*}; what=${p#*:}
    { printf '.TH %s 1 "%s" "sonard %s" "User Commands"\n.SH NAME\n%s \\- %s\n.SH SYNOPSIS AND OPTIONS\n.nf\n' \
          "$(echo "$name" | tr a-z A-Z)" "$(date -u -d @"${SOURCE_DATE_EPOCH:-$(git log -1 --format=%ct 2> /dev/null || date +%s)}" +%Y-%m-%d)" \
          "$V" "$name" "$what"
      case $name in
          sonar-view) python3 "$R/usr/share/sonard/view/sonar_view.py" --help ;;
          sonar-ros2) python3 "$R/usr/share/sonard/ros2/sonard_ros2.py" --help ;;
          *) "$R/usr/bin/$name" --help ;;
      esac 2>&1 | sed -e 's/\\/\\e/g' -e "s/^\([.']\)/\\\\\&\1/"
      printf '.fi\n.SH SEE ALSO\n/usr/share/doc/sonard/README.md, /usr/share/doc/sonard/configuration.md\n'
    } | gzip -9n > "$R/usr/share/man/man1/$name.1.gz"
done
install -m 0755 tools/pkg/deb/postinst tools/pkg/deb/prerm tools/pkg/deb/postrm "$R/DEBIAN/"
echo /etc/sonard/sonard.conf > "$R/DEBIAN/conffiles"
# Library dependencies: dpkg-shlibdeps wants a debian/control beside it.
dep="libc6, liblcm1"
if command -v dpkg-shlibdeps > /dev/null; then
    w="$B/deb/shlib"
    mkdir -p "$w/debian"
    printf 'Source: sonard\n\nPackage: sonard\nArchitecture: any\n' > "$w/debian/control"
    got=$(cd "$w" && dpkg-shlibdeps -O "$OLDPWD/$R/usr/bin/sonard" "$OLDPWD/$R/usr/bin/sonar-feed" 2> /dev/null | sed -n 's/^shlibs:Depends=//p') || got=""
    [ -n "$got" ] && dep=$got
fi
size=$(du -sk --exclude=DEBIAN "$R" | cut -f1)
sed -e "s/@VERSION@/$V/" -e "s/@ARCH@/$A/" -e "s/@SIZE@/$size/" -e "s/@DEPENDS@/$dep/" tools/pkg/deb/control.in > "$R/DEBIAN/control"
(cd "$R" && find . -type f ! -path './DEBIAN/*' -printf '%P\0' | sort -z | xargs -0 md5sum) > "$R/DEBIAN/md5sums"
dpkg-deb --root-owner-group -Zxz --build "$R" "$OUT" > /dev/null
echo "deb: $OUT ($(du -k "$OUT" | cut -f1) KB; Depends: $dep)"
