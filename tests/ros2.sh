#!/bin/sh
# ros2.sh -- the ROS 2 bridge (tools/ros2/sonard_ros2.py) against sonard's LCM: sonard drives sonar-feed's activity scene
# (a struggler) and publishes on a udpm bus, the bridge publishes it on ROS 2, tests/ros2_check.py compares the two; all inside a
# network namespace of its own, so neither LCM's multicast nor DDS's discovery leaves the machine's loopback.
# Usage: sh tests/ros2.sh BUILD_DIR. Ends with "ros2: N passed, N failed".
set -u
B=${1:-build}
T=$(mktemp -d /tmp/sonard-ros2.XXXXXX)
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/lib.sh"
need_netns ros2 "a network namespace for a private LCM bus and DDS"
cat > "$T/run.sh" <<EOS
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 3
ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST timeout 300 .venv-ros2/bin/python tests/ros2_check.py --build "$B" \\
    --lcm 'udpm://239.255.76.67:7667?ttl=0' --tmp "$T" > "$T/check.out" 2>&1
echo \$? > "$T/rc"
EOS
$NETNS sh "$T/run.sh"
cat "$T/check.out"
sed 's/^/    bridge: /' "$T/bridge.err" 2> /dev/null | head -10
tally ros2 "$T/check.out" "$T/rc"
