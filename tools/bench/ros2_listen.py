"""ros2_listen.py -- for tools/bench/ros2_cost.sh: an rclpy node that takes every topic the bridge publishes (so DDS
delivers them, as to a robot's nodes) for --seconds, then prints what it got per topic as JSON."""
import argparse
import json
import sys
import time


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, required=True)
    ap.add_argument("--ns", default="/sonar")
    a = ap.parse_args()
    import rclpy
    import rclpy.executors
    from diagnostic_msgs.msg import DiagnosticArray
    from rclpy.node import Node
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Image, LaserScan, PointCloud2
    from visualization_msgs.msg import MarkerArray
    rclpy.init()
    node = Node("ros2_listen")
    got = {}

    def count(topic):
        return lambda m: got.__setitem__(topic, got.get(topic, 0) + 1)
    for typ, topic, qos in ((LaserScan, "scan", qos_profile_sensor_data), (Image, "image", qos_profile_sensor_data),
                            (MarkerArray, "detections", 10), (PointCloud2, "detections/cloud", 10),
                            (MarkerArray, "tracks", 10), (DiagnosticArray, "/diagnostics", 10)):
        full = topic if topic.startswith("/") else f"{a.ns}/{topic}"
        node.create_subscription(typ, full, count(full), qos)
    t_end = time.monotonic() + a.seconds
    try:
        while time.monotonic() < t_end:
            rclpy.spin_once(node, timeout_sec=0.05)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass  # SIGTERM: what came so far
    print(json.dumps(got), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
