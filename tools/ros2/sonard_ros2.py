#!/usr/bin/env python3
"""sonard_ros2.py -- sonard's LCM as ROS 2 topics: detections, tracks and diagnostics for RViz, Foxglove and a ROS robot.

  sonard_ros2.py [--lcm URL] [--prefix P] [--types build/lcm/python] [--ros-args -r __ns:=/sonar -p frame_id:=sonar_link]

It reads sonard's SONAR_OBSTACLES, SONAR_BEAM, SONAR_CONFIG, SONAR_DETECTIONS, SONAR_TRACKS and SONAR_STATUS (with
sonard's --channel-prefix P) and publishes, under the node's namespace, stamped from sonard's utime, in the frame
`frame_id` (a ROS parameter, default sonar_link):

  scan               sensor_msgs/LaserScan            the obstacle map: the nearest echo in each 5-degree sector, the
                                                      figures of MAVLink's OBSTACLE_DISTANCE; counterclockwise from
                                                      ahead, NaN unknown, +inf scanned and clear (REP 117)
                                                      (sensor-data QoS)
  image              sensor_msgs/Image (mono8)        the fan: each raw beam drawn into an image_size square, the sonar
                                                      at its centre, ahead up, starboard right, the beam's range to the
                                                      edge; at most image_hz a second (sensor-data QoS)
  detections         visualization_msgs/MarkerArray   each detection's hull, a line strip coloured by kind
  detections/cloud   sensor_msgs/PointCloud2          a point per detection (x, y, z, area, kind, intensity, track)
  tracks             visualization_msgs/MarkerArray   each track: a sphere, its ID, activity and existence as text,
                                                      red while it has an alarm; a trail of its last 10 sweeps
  /diagnostics       diagnostic_msgs/DiagnosticArray  the link, beams a second, the survey, the alarms standing
                                                      (ERROR while a struggle alarm stands)

Frames: sonard's body frame has x ahead and y to starboard; ROS's (REP 103) has y to port, so y is negated.
Markers, cloud and diagnostics use reliable QoS, depth 10; scan and image sensor-data QoS (best effort, depth 5): a
subscriber that cannot keep up loses the oldest, never a growing queue.

Odometry in (parameter odom_topic, default "" for none): each nav_msgs/Odometry becomes a SONAR_POSE (sonar.pose_t) on
the same LCM, for sonard's --pose-lcm: the world frame's north is the odometry frame's y, east its x (REP 103's ENU), the
heading its yaw turned clockwise from north. Refused, counted by reason on /diagnostics and said once each: another
header.frame_id than odom_frame (default "odom"), a stamp not after the last one taken, a NaN or infinity. The pose is
the odometry's child frame's: a sonar mounted away from it is not corrected for (docs/ros2.md).
The bridge has no control path: nothing it receives reaches the sonar or changes sonard's settings; a pose only moves
the frame sonard reports in.

LCM in: udpm:// (LCM's default) through tools/view/lcm_udpm.py, in plain Python; other URLs need LCM's Python binding.
ROS 2: rclpy from `make ros2` (.venv-ros2, Kilted's wheels) or from a sourced ROS 2 distribution; without it, one line
saying how to get it and exit 2. An LCM message that does not decode is counted (on the diagnostics) and skipped.
"""
import argparse
import array
import math
import os
import re
import select
import struct
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "data"))  # fan.py (installed beside this file)
KIND_NAMES = ("object", "structure", "static since start", "wall echo")
# object green, structure grey, static blue, a wall's echo dark grey
KIND_RGB = ((0.1, 0.9, 0.2), (0.5, 0.5, 0.5), (0.2, 0.6, 1.0), (0.3, 0.3, 0.35))
ACTIVITY_NAMES = ("unknown", "moving", "standing", "struggling")
ALARM_STRUGGLE = 1  # SONAR_ALARM_STRUGGLE (include/sonar/activity.h)
LINK_STATES = ("down", "connecting", "probing", "scanning", "auto-transmit", "stopping", "stopped", "passive")
LINK_OK = (3, 4, 7)  # enum sonar_ping360_state: beams are coming (scanning, auto-transmit, passive)
SURVEY_STATES = ("none", "in use", "no longer fits")
CLOUD_FIELDS = (("x", 7), ("y", 7), ("z", 7), ("area", 7), ("kind", 7), ("intensity", 7), ("track", 7))  # FLOAT32
DEPTH = 10
TRAIL = 10  # sweeps a track's trail shows
OBS_UNKNOWN = 65535  # SONAR_OBS_UNKNOWN (include/sonar/obstacle.h): not scanned within a sweep, or a masked arc


def stamp_of(utime):
    """A builtin_interfaces/Time from sonard's utime (us since the epoch)."""
    from builtin_interfaces.msg import Time
    return Time(sec=int(utime // 1000000), nanosec=int(utime % 1000000) * 1000)


class Odom:
    """nav_msgs/Odometry in, SONAR_POSE out (see the module's comment); refusals counted by reason."""

    def __init__(self, node, topic, frame, lc, channel, pose_t):
        from nav_msgs.msg import Odometry
        from rclpy.qos import QoSProfile, ReliabilityPolicy, HistoryPolicy
        self.node, self.frame, self.lc, self.channel, self.pose_t = node, frame, lc, channel, pose_t
        self.counts = {"taken": 0, "other_frame": 0, "stamp_backwards": 0, "not_finite": 0}
        self.last_us, self.said = None, set()
        qos = QoSProfile(depth=DEPTH, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)
        node.create_subscription(Odometry, topic, self.on, qos)

    def refuse(self, reason, text):
        self.counts[reason] += 1
        if reason not in self.said:
            self.said.add(reason)
            self.node.get_logger().warning(f"odometry refused: {text} (said once; each counted on /diagnostics)")

    def on(self, m):
        p, q = m.pose.pose.position, m.pose.pose.orientation
        us = m.header.stamp.sec * 1000000 + m.header.stamp.nanosec // 1000
        if m.header.frame_id != self.frame:
            return self.refuse("other_frame", f"header.frame_id {m.header.frame_id!r} is not odom_frame {self.frame!r}")
        if not all(math.isfinite(v) for v in (p.x, p.y, q.x, q.y, q.z, q.w)):
            return self.refuse("not_finite", f"a NaN or infinity in the pose at stamp {us} us")
        if self.last_us is not None and us < self.last_us:
            return self.refuse("stamp_backwards", f"stamp {us} us is before the last one taken, {self.last_us} us")
        self.last_us = us
        yaw_enu = math.degrees(math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z)))
        pt = self.pose_t()
        pt.utime, pt.north_m, pt.east_m, pt.yaw_deg = us, float(p.y), float(p.x), (90.0 - yaw_enu) % 360.0
        self.lc.publish(self.channel, pt.encode())
        self.counts["taken"] += 1


class Bridge:
    """sonard's messages to ROS messages, published through `node` (an rclpy Node, or anything with
    create_publisher(type, topic, qos): lcm2mcap --ros2 writes them into a bag)."""

    def __init__(self, node, params, clock=None):
        """clock: seconds, monotonic, when live (images are then also limited to image_hz of it); None for a log."""
        from diagnostic_msgs.msg import DiagnosticArray
        from rclpy.qos import QoSProfile, ReliabilityPolicy, HistoryPolicy, qos_profile_sensor_data
        from sensor_msgs.msg import Image, LaserScan, PointCloud2
        from visualization_msgs.msg import MarkerArray
        qos = QoSProfile(depth=DEPTH, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)
        self.frame = params["frame_id"]
        from fan import Fan
        self.fan = Fan(params["image_size"])
        self.image_us = int(1e6 / params["image_hz"])
        self.image_at = None      # utime of the last image published
        self.clock, self.image_wall = clock, -math.inf
        self.lost = lambda: 0     # LCM messages lost on the way (the bus's count, once lcm_setup has it)
        self.angle_offset = 0.0   # SONAR_CONFIG's, degrees
        self.images = self.images_skipped = self.scans = 0
        self.pub_img = node.create_publisher(Image, "image", qos_profile_sensor_data)
        self.pub_scan = node.create_publisher(LaserScan, "scan", qos_profile_sensor_data)
        self.odom = None          # an Odom once lcm_setup has the bus
        self.pub_det = node.create_publisher(MarkerArray, "detections", qos)
        self.pub_cloud = node.create_publisher(PointCloud2, "detections/cloud", qos)
        self.pub_trk = node.create_publisher(MarkerArray, "tracks", qos)
        self.pub_diag = node.create_publisher(DiagnosticArray, "/diagnostics", qos)
        self.bad = {}             # channel -> messages that did not decode
        self.received = {}        # channel -> messages received
        self.published = 0
        self.track_of = {}        # sweep -> {detection index: track id}, the last few sweeps
        self.pending = {}         # sweep -> detections_t waiting for its tracks (the cloud carries the track IDs)
        self.alarms = set()       # track IDs with a struggle alarm standing
        self.trails = {}          # track ID -> its last TRAIL positions (north, east in the world; else x, y)
        self.yaw_of = {}          # sweep -> the heading its detections were placed at (0 in the body frame)
        self.beams = []           # (status utime in s, status beams) of the last statuses

    def summary(self):
        """One line of what came in and went out, for the log at exit."""
        got = ", ".join(f"{k} {v}" for k, v in sorted(self.received.items())) or "none"
        return (f"sonard_ros2: LCM in: {got}; {self.lost()} lost on the way, {sum(self.bad.values())} did not decode; "
                f"ROS out: {self.scans} scans, {self.images} images ({self.images_skipped} beams drawn, not sent), "
                f"{self.published} marker arrays")

    def header(self, utime):
        from std_msgs.msg import Header
        return Header(stamp=stamp_of(utime), frame_id=self.frame)

    def obstacles(self, m):
        """SONAR_OBSTACLES as a LaserScan: sector k (k x sector_deg clockwise from ahead) is ROS's -k x sector_deg, so
        the ranges run counterclockwise from ahead through the sectors k = 0, n - 1, n - 2, ..."""
        from sensor_msgs.msg import LaserScan
        n = m.count
        if n <= 0:
            return
        inc = math.radians(m.sector_deg)
        ranges = []
        for j in range(n):
            d = m.distance_cm[(n - j) % n]
            ranges.append(math.nan if d == OBS_UNKNOWN else math.inf if d > m.max_cm else d / 100.0)
        self.pub_scan.publish(LaserScan(header=self.header(m.utime), angle_min=0.0, angle_max=inc * (n - 1),
                                        angle_increment=inc, time_increment=0.0, scan_time=0.0,
                                        range_min=m.min_cm / 100.0, range_max=m.max_cm / 100.0,
                                        ranges=array.array("f", ranges)))
        self.scans += 1

    def config(self, m):
        self.angle_offset = float(m.angle_offset)

    def beam(self, m):
        """A raw beam into the fan; the fan out when image_hz allows (the beams between are drawn, not sent)."""
        from sensor_msgs.msg import Image
        self.fan.draw(m.angle * 0.9 + self.angle_offset, m.samples, m.number_of_samples)
        wall = self.clock() if self.clock is not None else None  # a log: beam time alone
        if (self.image_at is not None and 0 <= m.utime - self.image_at < self.image_us) or \
                (wall is not None and wall - self.image_wall < self.image_us * 1e-6):  # a fast replay: both clocks
            self.images_skipped += 1
            return
        self.image_at = m.utime
        if wall is not None:
            self.image_wall = wall
        n = self.fan.size
        self.pub_img.publish(Image(header=self.header(m.utime), height=n, width=n, encoding="mono8", is_bigendian=0,
                                   step=n, data=array.array("B", self.fan.img.tobytes())))
        self.images += 1

    def detections(self, m):
        from geometry_msgs.msg import Point
        from visualization_msgs.msg import Marker, MarkerArray
        arr = MarkerArray()
        clear = Marker(header=self.header(m.utime), ns="detections", action=Marker.DELETEALL)
        arr.markers.append(clear)
        for i, d in enumerate(m.detections):
            mk = Marker(header=self.header(m.utime), ns="detections", id=i, type=Marker.LINE_STRIP, action=Marker.ADD)
            mk.pose.position.x, mk.pose.position.y = float(d.x_m), -float(d.y_m)
            mk.pose.orientation.w = 1.0
            mk.scale.x = 0.05
            r, g, b = KIND_RGB[d.kind] if 0 <= d.kind < len(KIND_RGB) else (1.0, 1.0, 1.0)
            mk.color.r, mk.color.g, mk.color.b, mk.color.a = r, g, b, 1.0
            pts = [Point(x=float(hx - d.x_m), y=-float(hy - d.y_m), z=0.0) for hx, hy in zip(d.hull_x, d.hull_y)]
            mk.points = pts + pts[:1]
            mk.text = KIND_NAMES[d.kind] if 0 <= d.kind < len(KIND_NAMES) else str(d.kind)
            arr.markers.append(mk)
        self.pub_det.publish(arr)
        self.published += 1
        self.pending[m.sweep] = m
        self.yaw_of = {k: v for k, v in self.yaw_of.items() if k >= m.sweep - 4}
        self.yaw_of[m.sweep] = float(m.yaw_deg) if m.world else 0.0  # the body frame's heading, for the trails
        self.flush_clouds(m.sweep)

    def flush_clouds(self, newest):
        """Each sweep's cloud once its tracks are in, or two sweeps on without them (the tracks are off)."""
        for sweep in sorted(self.pending):
            if sweep in self.track_of or sweep < newest - 1:
                self.cloud(self.pending.pop(sweep), self.track_of.get(sweep, {}))
        for sweep in [s for s in self.track_of if s < newest - 4]:
            del self.track_of[sweep]

    def cloud(self, m, tracks):
        from sensor_msgs.msg import PointCloud2, PointField
        fields = [PointField(name=n, offset=4 * k, datatype=t, count=1) for k, (n, t) in enumerate(CLOUD_FIELDS)]
        data = b"".join(struct.pack("<7f", d.x_m, -d.y_m, 0.0, d.area_m2, float(d.kind), d.mean_intensity,
                                    float(tracks.get(i, 0))) for i, d in enumerate(m.detections))
        msg = PointCloud2(header=self.header(m.utime), height=1, width=len(m.detections), fields=fields,
                          is_bigendian=False, point_step=28, row_step=28 * len(m.detections), data=array.array("B", data),
                          is_dense=True)
        self.pub_cloud.publish(msg)

    def tracks(self, m):
        from visualization_msgs.msg import Marker, MarkerArray
        arr = MarkerArray()
        arr.markers.append(Marker(header=self.header(m.utime), ns="tracks", action=Marker.DELETEALL))
        shown = {}
        for t in m.tracks:
            if t.detection >= 0:
                shown[t.detection] = t.id
            alarm = bool(t.alarms & ALARM_STRUGGLE)
            (self.alarms.add if alarm else self.alarms.discard)(t.id)
            for k, kind in enumerate((Marker.SPHERE, Marker.TEXT_VIEW_FACING)):
                mk = Marker(header=self.header(m.utime), ns="tracks", id=2 * t.id + k, type=kind, action=Marker.ADD)
                mk.pose.position.x, mk.pose.position.y = float(t.x_m), -float(t.y_m)
                mk.pose.position.z = 0.0 if k == 0 else 0.6
                mk.pose.orientation.w = 1.0
                mk.scale.x = mk.scale.y = mk.scale.z = 0.4 if k == 0 else 0.3
                mk.color.r, mk.color.g, mk.color.b, mk.color.a = (1.0, 0.1, 0.1, 1.0) if alarm else (1.0, 0.8, 0.1, 1.0)
                act = ACTIVITY_NAMES[t.activity] if 0 <= t.activity < len(ACTIVITY_NAMES) else str(t.activity)
                mk.text = f"{t.id} {act} {t.existence:.2f}" + (" ALARM" if alarm else "")
                arr.markers.append(mk)
            arr.markers.extend(self.trail(t, m))
        ended = self.alarms - {t.id for t in m.tracks}
        self.alarms -= ended
        for gone in set(self.trails) - {t.id for t in m.tracks}:
            del self.trails[gone]
        self.pub_trk.publish(arr)
        self.published += 1
        self.track_of[m.sweep] = shown
        self.flush_clouds(m.sweep)

    def trail(self, t, m):
        """The track's last TRAIL positions as a line strip (ns tracks/trail, id the track's) in the body frame now:
        kept in the world when the track is (north, east), turned by the sweep's heading into the body frame at
        the track's position now, so a trail seen from a moving vehicle stays where the track went."""
        from geometry_msgs.msg import Point
        from visualization_msgs.msg import Marker
        pts = self.trails.setdefault(t.id, [])
        pts.append((t.north_m, t.east_m) if t.world else (t.x_m, t.y_m))
        del pts[:-TRAIL]
        yaw = self.yaw_of.get(m.sweep)
        if len(pts) < 2 or (t.world and yaw is None):
            return []
        mk = Marker(header=self.header(m.utime), ns="tracks/trail", id=t.id, type=Marker.LINE_STRIP, action=Marker.ADD)
        mk.pose.orientation.w = 1.0
        mk.scale.x = 0.05
        mk.color.r, mk.color.g, mk.color.b, mk.color.a = 1.0, 0.8, 0.1, 0.6
        for a, b in pts:
            if t.world:
                c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
                dn, de = a - t.north_m, b - t.east_m
                x, y = t.x_m + c * dn + s * de, t.y_m - s * dn + c * de
            else:
                x, y = a, b
            mk.points.append(Point(x=float(x), y=-float(y), z=0.0))
        return [mk]

    def status(self, m):
        from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
        now = m.utime * 1e-6  # sonard's clock: the same figure live and from a log
        self.beams = [b for b in self.beams if now - b[0] <= 5.0] + [(now, int(m.beams))]
        rate = (self.beams[-1][1] - self.beams[0][1]) / (self.beams[-1][0] - self.beams[0][0]) if len(self.beams) > 1 and \
            self.beams[-1][0] > self.beams[0][0] else 0.0
        st = DiagnosticStatus(name="sonard", hardware_id=m.link or "sonard")
        if self.alarms:
            st.level, st.message = DiagnosticStatus.ERROR, f"struggle alarm: track {', '.join(map(str, sorted(self.alarms)))}"
        elif m.link_state not in LINK_OK:
            name = LINK_STATES[m.link_state] if 0 <= m.link_state < len(LINK_STATES) else str(m.link_state)
            st.level, st.message = DiagnosticStatus.WARN, f"the sonar is {name}"
        else:
            st.level, st.message = DiagnosticStatus.OK, "running"
        sv = getattr(m, "survey_state", 0)
        values = {"link": m.link, "link_state": m.link_state, "beams": m.beams, "beams_per_s": f"{rate:.1f}",
                  "sweeps": m.sweeps, "tracks": m.tracks, "alarms": ",".join(map(str, sorted(self.alarms))),
                  "survey": SURVEY_STATES[sv] if 0 <= sv < len(SURVEY_STATES) else str(sv),
                  "blank_beams": getattr(m, "blank_beams", 0), "interference_beams": getattr(m, "interference_beams", 0),
                  "bridge_published": self.published, "bridge_images": self.images, "bridge_scans": self.scans,
                  "bridge_images_skipped": self.images_skipped,
                  "bridge_undecoded": sum(self.bad.values()), "bridge_lcm_lost": self.lost()}
        if self.odom is not None:
            values.update({f"odometry_{k}": v for k, v in self.odom.counts.items()})
        st.values = [KeyValue(key=k, value=str(v)) for k, v in values.items()]
        self.pub_diag.publish(DiagnosticArray(header=self.header(m.utime), status=[st]))


def handlers(types, prefix, bridge):
    """{channel: handler(channel, data)}: each of sonard's channels the bridge reads, decoded and handed to the
    bridge; a message that does not decode is counted and skipped. The live bus and lcm2mcap --ros2 share it."""
    sys.path.insert(0, types)
    from sonar import beam_t, config_t, detections_t, obstacles_t, status_t, tracks_t  # noqa: E402 (from --types)

    def on(name, typ, handle):
        def handler(channel, data):
            bridge.received[name] = bridge.received.get(name, 0) + 1
            try:
                m = typ.decode(data)
            except Exception:  # a message of another sonard or garbage: counted, skipped
                bridge.bad[name] = bridge.bad.get(name, 0) + 1
                return
            handle(m)
        return prefix + name, handler
    return dict(on(*h) for h in (("SONAR_OBSTACLES", obstacles_t, bridge.obstacles), ("SONAR_BEAM", beam_t, bridge.beam),
                                 ("SONAR_CONFIG", config_t, bridge.config),
                                 ("SONAR_DETECTIONS", detections_t, bridge.detections),
                                 ("SONAR_TRACKS", tracks_t, bridge.tracks), ("SONAR_STATUS", status_t, bridge.status)))


def lcm_setup(url, types, prefix, bridge, params, node):
    if url is None or url.startswith("udpm://"):
        sys.path.insert(0, os.path.join(HERE, "..", "view"))
        from lcm_udpm import Udpm
        lc = Udpm(url)
    else:
        import lcm
        lc = lcm.LCM(url)
    for channel, handler in handlers(types, prefix, bridge).items():
        lc.subscribe(re.escape(channel) + "$", handler)
    bridge.lost = lambda: getattr(lc, "lost", 0)  # udpm's count; LCM's own binding does not say
    if params["odom_topic"]:
        from sonar import pose_t  # noqa: E402
        bridge.odom = Odom(node, params["odom_topic"], params["odom_frame"], lc, f"{prefix}SONAR_POSE", pose_t)
    return lc


# name: (default, check, what it must be); refused by name at start, as sonard's options are
PARAMS = {
    "frame_id": ("sonar_link", lambda v: isinstance(v, str) and v and not any(c.isspace() for c in v),
                 "a ROS frame name, not empty, no spaces"),
    "image_size": (400, lambda v: isinstance(v, int) and 64 <= v <= 2048, "pixels a side, 64..2048"),
    "image_hz": (5.0, lambda v: isinstance(v, (int, float)) and 0.1 <= v <= 50, "images a second at most, 0.1..50 (a float: 10.0)"),
    "odom_topic": ("", lambda v: isinstance(v, str) and not any(c.isspace() for c in v),
                   "a topic name (empty: no odometry in), no spaces"),
    "odom_frame": ("odom", lambda v: isinstance(v, str) and v and not any(c.isspace() for c in v),
                   "the odometry's header.frame_id, not empty, no spaces"),
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lcm", default=os.environ.get("LCM_DEFAULT_URL"), help="LCM URL (default LCM's own)")
    ap.add_argument("--prefix", default="", help="sonard's --channel-prefix")
    ap.add_argument("--types", default=os.environ.get("SONARD_LCM_PY", "build/lcm/python"),
                    help="the directory of sonard's generated LCM Python types")
    ap.add_argument("--max-seconds", type=float, default=0.0, help="stop after this long (0: run until stopped)")
    argv = sys.argv[1:]
    ros_args = argv[argv.index("--ros-args"):] if "--ros-args" in argv else []
    a = ap.parse_args(argv[:len(argv) - len(ros_args)])
    try:
        import rclpy
        import rclpy.executors
        from rclpy.node import Node
    except ImportError:
        print("sonard_ros2: no ROS 2 found: run `make ros2` and use .venv-ros2/bin/python, or source your ROS 2 "
              "distribution's setup.bash", file=sys.stderr)
        return 2
    if not os.path.isdir(os.path.join(a.types, "sonar")):
        print(f"sonard_ros2: --types {a.types}: no generated LCM types there (make builds them in build/lcm/python)",
              file=sys.stderr)
        return 2
    rclpy.init(args=["sonard_ros2"] + ros_args)
    node = Node("sonard_ros2")
    params = {}
    for name, (default, ok, what) in PARAMS.items():
        try:
            v = node.declare_parameter(name, default).value
        except Exception as e:  # a value of another type than the default's
            v, what = None, f"{what} ({e.__class__.__name__})"
        if not ok(v):
            print(f"sonard_ros2: parameter {name} {v!r}: {what}", file=sys.stderr)
            node.destroy_node()
            rclpy.shutdown()
            return 2
        params[name] = v
    bridge = Bridge(node, params, clock=time.monotonic)
    lc = lcm_setup(a.lcm, a.types, a.prefix, bridge, params, node)
    node.get_logger().info(f"sonard_ros2: LCM {a.lcm or 'default'}{' prefix ' + a.prefix if a.prefix else ''} -> "
                           f"{node.get_namespace()} in frame {params['frame_id']}"
                           + (f"; odometry {params['odom_topic']} -> SONAR_POSE" if params["odom_topic"] else ""))
    t_end = time.monotonic() + a.max_seconds if a.max_seconds > 0 else math.inf
    try:
        while rclpy.ok() and time.monotonic() < t_end:
            ready, _, _ = select.select([lc.fileno()], [], [], 0.05)
            while ready and rclpy.ok():  # everything waiting, then ROS's turn
                lc.handle()
                ready, _, _ = select.select([lc.fileno()], [], [], 0)
            if rclpy.ok():
                rclpy.spin_once(node, timeout_sec=0)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    except Exception:  # SIGTERM's shutdown between the check and the call: a stop, not a fault
        if rclpy.ok():
            raise
    print(bridge.summary(), file=sys.stderr, flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
