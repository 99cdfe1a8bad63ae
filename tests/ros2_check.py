"""ros2_check.py -- the ROS 2 bridge against the LCM it came from (tests/ros2.sh runs it in a network namespace): sonard
drives sonar-feed's activity scene (a struggler; eight times the device's pace) and publishes on a udpm bus, tools/ros2/sonard_ros2.py publishes it on ROS 2, and this node subscribes to both. Each
SONAR_DETECTIONS has its MarkerArray and its PointCloud2 with the same stamp, a marker and a point per detection at its
centroid (y negated: ROS's y is to port) within 1 mm; each SONAR_TRACKS its MarkerArray with the same track IDs; a struggle
alarm turns /diagnostics to ERROR; a message that does not decode is counted there; each fan image holds the beam it is
stamped with along that beam's axis; each SONAR_OBSTACLES has its LaserScan, sector by sector; odometry published here reaches sonard as SONAR_POSE and turns its detections into
the world frame at that pose, and bad odometry is refused, counted by reason; a replay's LCM log made a ROS 2 bag by
lcm2mcap --ros2 reads back as the log says. Prints [  PASS  ] / [  FAIL  ] lines.
Runs on .venv-ros2's python (rclpy) with sonard's generated LCM types and tools/view/lcm_udpm.py.
"""
import argparse
import math
import os
import select
import statistics
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tools", "view"))
fails = 0


def check(name, ok):
    global fails
    print(f"[  {'PASS' if ok else 'FAIL'}  ] {name}", flush=True)
    fails += not ok


def stamp_us(h):
    return h.stamp.sec * 1000000 + h.stamp.nanosec // 1000


def scan_matches(m, ranges, inc, range_max):
    """A LaserScan's ranges against the SONAR_OBSTACLES it came from: sector k (k x 5 degrees clockwise) is entry
    (72 - k) % 72, within 1 cm; unknown NaN, clear +inf. Returns (all agree, echoes compared)."""
    good = len(ranges) == m.count and abs(inc - math.radians(5)) < 1e-6 and abs(range_max - m.max_cm / 100) < 0.01
    echoes = 0
    for k in range(m.count if good else 0):
        d, r = m.distance_cm[k], ranges[(m.count - k) % m.count]
        if d == 65535:
            good &= math.isnan(r)
        elif d > m.max_cm:
            good &= math.isinf(r) and r > 0
        else:
            good &= abs(r - d / 100) <= 0.01
            echoes += 1
    return good, echoes


def bag_checks(a):
    """lcm2mcap --ros2 on a replay's LCM log: every message decodes back (mcap-ros2-support's decoder, from the
    bag's own definitions, and rclpy from the bytes alone, as ros2 bag play reads them) to what the log says."""
    import importlib
    import importlib.machinery
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory
    from rclpy.serialization import deserialize_message
    from sonar import detections_t, obstacles_t, tracks_t
    t = a.tmp
    subprocess.run([os.path.join(a.build, "sonar-sim"), "--scene", "activity", "--out", f"{t}/bag.csv", "--truth",
                    f"{t}/bag.json", "--sweeps", "6"], check=True, capture_output=True)
    subprocess.run([os.path.join(a.build, "sonard"), "--replay", f"{t}/bag.csv", "--lcm", f"file://{t}/bag.lcm?mode=w",
                    "--quiet"], check=True, capture_output=True)
    tool = os.path.join(HERE, "..", "tools", "data", "lcm2mcap")
    r = subprocess.run([sys.executable, tool, "--ros2", f"{t}/bag.lcm", f"{t}/bag.mcap", "--types",
                        os.path.join(a.build, "lcm", "python")], capture_output=True, text=True, timeout=120)
    print("    " + r.stderr.strip().replace("\n", "\n    "))
    check(f"lcm2mcap --ros2 writes the replay's bag (exit {r.returncode})", r.returncode == 0)
    lm = importlib.machinery.SourceFileLoader("lcm2mcap_mod", tool).load_module()
    log = {"SONAR_OBSTACLES": [], "SONAR_DETECTIONS": [], "SONAR_TRACKS": []}
    typ = {"SONAR_OBSTACLES": obstacles_t, "SONAR_DETECTIONS": detections_t, "SONAR_TRACKS": tracks_t}
    with open(f"{t}/bag.lcm", "rb") as f:
        for _ut, ch, data in lm.read_events(f):
            if ch in log:
                log[ch].append(typ[ch].decode(data))
    got, raw_ok, n = {}, 0, 0
    decoders = DecoderFactory()
    with open(f"{t}/bag.mcap", "rb") as f:
        rd = make_reader(f)
        profile = rd.get_header().profile
        for schema, channel, msg in rd.iter_messages():
            n += 1
            dec = decoders.decoder_for(channel.message_encoding, schema)(msg.data)
            pkg, _, name = schema.name.split("/")
            cls = getattr(importlib.import_module(f"{pkg}.msg"), name)
            raw_ok += type(deserialize_message(msg.data, cls)).__name__ == name and channel.message_encoding == "cdr"
            got.setdefault(channel.topic, []).append((msg.log_time, dec))
    counts = {k: len(v) for k, v in got.items()}
    check(f"the bag: profile ros2, {n} messages: {counts}; as many scans, marker arrays and clouds as the log's "
          f"SONAR_OBSTACLES ({len(log['SONAR_OBSTACLES'])}), SONAR_DETECTIONS ({len(log['SONAR_DETECTIONS'])}) and "
          f"SONAR_TRACKS ({len(log['SONAR_TRACKS'])}); every message read back by rclpy from its bytes ({raw_ok})",
          profile == "ros2" and n == raw_ok and counts.get("/sonar/scan", 0) == len(log["SONAR_OBSTACLES"]) > 0
          and counts.get("/sonar/detections", 0) == len(log["SONAR_DETECTIONS"]) > 0
          and counts.get("/sonar/detections/cloud", 0) == len(log["SONAR_DETECTIONS"])
          and counts.get("/sonar/tracks", 0) == len(log["SONAR_TRACKS"]) and counts.get("/sonar/image", 0) > 0)
    scans = all(scan_matches(m, list(d.ranges), d.angle_increment, d.range_max)[0] and lt == m.utime * 1000
                for m, (lt, d) in zip(log["SONAR_OBSTACLES"], got.get("/sonar/scan", [])))
    dets = all(len([k for k in d.markers if k.action == 0]) == m.count and
               all(abs(k.pose.position.x - x.x_m) <= 0.001 and abs(k.pose.position.y + x.y_m) <= 0.001
                   for k, x in zip([k for k in d.markers if k.action == 0], m.detections))
               for m, (lt, d) in zip(log["SONAR_DETECTIONS"], got.get("/sonar/detections", [])))
    trks = all({k.id // 2 for k in d.markers if k.action == 0 and k.ns == "tracks"} == {x.id for x in m.tracks}
               for m, (lt, d) in zip(log["SONAR_TRACKS"], got.get("/sonar/tracks", [])))
    # The Foxglove layout shipped in docs names only topics the bridge publishes.
    import json
    import re as _re
    layout = json.load(open(os.path.join(HERE, "..", "docs", "foxglove-ros2.json")))
    named = set(_re.findall(r'"(/[a-z_/]+?)(?:[.]|")', json.dumps(layout["configById"])))
    check(f"docs/foxglove-ros2.json: its panels name {sorted(named)}, each a topic in the bag or /diagnostics",
          named and named <= set(got) | {"/diagnostics"})
    check(f"decoded from the bag's own definitions: each scan's sectors, each detection's marker (1 mm) and each "
          f"sweep's track IDs as the log has them, at its utime (scans {scans}, detections {dets}, tracks {trks})",
          scans and dets and trks and got.get("/sonar/scan"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--lcm", required=True)
    ap.add_argument("--tmp", required=True)
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "lcm", "python"))
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
    from lcm_udpm import Udpm
    from nav_msgs.msg import Odometry
    from rclpy.node import Node
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Image, LaserScan, PointCloud2
    from sonar import beam_t, detections_t, obstacles_t, tracks_t
    from visualization_msgs.msg import Marker, MarkerArray

    bridge_cmd = [sys.executable, os.path.join(HERE, "..", "tools", "ros2", "sonard_ros2.py"), "--lcm", a.lcm,
                  "--types", os.path.join(a.build, "lcm", "python"), "--ros-args", "-r", "__ns:=/sonar",
                  "-p", "odom_topic:=odom"]
    # Bad input first: no ROS 2 (the system's python, which has no rclpy), and a frame_id that is not one.
    r = subprocess.run(["/usr/bin/python3", bridge_cmd[1]] + bridge_cmd[2:], capture_output=True, text=True, timeout=60)
    check(f"no ROS 2: one line saying how to get it, exit 2 (exit {r.returncode})",
          r.returncode == 2 and "make ros2" in r.stderr and len(r.stderr.strip().splitlines()) == 1)
    r = subprocess.run(bridge_cmd + ["-p", "frame_id:=a b"], capture_output=True, text=True, timeout=60)
    check(f"a frame_id with a space: refused by name at start, exit 2 (exit {r.returncode})",
          r.returncode == 2 and "parameter frame_id" in r.stderr)
    r = subprocess.run(bridge_cmd + ["-p", "image_size:=9"], capture_output=True, text=True, timeout=60)
    check(f"an image_size of 9: refused by name with its range, exit 2 (exit {r.returncode})",
          r.returncode == 2 and "parameter image_size 9: pixels a side, 64..2048" in r.stderr)

    rclpy.init()
    node = Node("ros2_check")
    ros = {"det": {}, "cloud": {}, "trk": {}, "diag": [], "t_det": {}}
    node.create_subscription(MarkerArray, "/sonar/detections",
                             lambda m: (ros["det"].__setitem__(stamp_us(m.markers[0].header), m),
                                        ros["t_det"].__setitem__(stamp_us(m.markers[0].header), time.monotonic())), 100)
    node.create_subscription(PointCloud2, "/sonar/detections/cloud", lambda m: ros["cloud"].__setitem__(stamp_us(m.header), m), 100)
    node.create_subscription(MarkerArray, "/sonar/tracks", lambda m: ros["trk"].__setitem__(stamp_us(m.markers[0].header), m), 100)
    node.create_subscription(DiagnosticArray, "/diagnostics", lambda m: ros["diag"].append(m), 100)
    ros["img"] = []
    node.create_subscription(Image, "/sonar/image", lambda m: ros["img"].append(m), qos_profile_sensor_data)
    ros["scan"] = {}
    node.create_subscription(LaserScan, "/sonar/scan", lambda m: ros["scan"].__setitem__(stamp_us(m.header), m),
                             qos_profile_sensor_data)
    odom_pub = node.create_publisher(Odometry, "/sonar/odom", 10)
    lc = Udpm(a.lcm)
    lcm = {"det": {}, "trk": {}, "t_det": {}, "beam": {}, "obs": {}}

    def on_obs(channel, data):
        m = obstacles_t.decode(data)
        lcm["obs"][m.utime] = m

    def on_beam(channel, data):
        m = beam_t.decode(data)
        lcm["beam"][m.utime] = m

    def on_det(channel, data):
        try:
            m = detections_t.decode(data)
        except ValueError:  # the garbage this check sends the bridge
            return
        lcm["det"][m.utime] = m
        lcm["t_det"][m.utime] = time.monotonic()

    def on_trk(channel, data):
        try:
            m = tracks_t.decode(data)
        except ValueError:
            return
        lcm["trk"][m.utime] = m
    lc.subscribe("SONAR_DETECTIONS$", on_det)
    lc.subscribe("SONAR_TRACKS$", on_trk)
    lc.subscribe("SONAR_BEAM$", on_beam)
    lc.subscribe("SONAR_OBSTACLES$", on_obs)

    def odom(frame="odom", x=-2.0, y=5.0, yaw_enu=0.0, t=None):
        """A still vehicle 5 m north and 2 m west of the origin facing east, in the odometry frame's ENU."""
        m = Odometry()
        t = time.time() if t is None else t
        m.header.stamp.sec, m.header.stamp.nanosec = int(t), int((t % 1) * 1e9)
        m.header.frame_id, m.child_frame_id = frame, "base_link"
        m.pose.pose.position.x, m.pose.pose.position.y = x, y
        m.pose.pose.orientation.z, m.pose.pose.orientation.w = math.sin(yaw_enu / 2), math.cos(yaw_enu / 2)
        odom_pub.publish(m)

    def pump(seconds):
        t_end = time.monotonic() + seconds
        while time.monotonic() < t_end:
            ready, _, _ = select.select([lc.fileno()], [], [], 0.01)
            while ready:
                lc.handle()
                ready, _, _ = select.select([lc.fileno()], [], [], 0)
            for _ in range(20):  # one callback a call: what came in this round, before the next
                rclpy.spin_once(node, timeout_sec=0)

    bridge = subprocess.Popen(bridge_cmd, stderr=open(os.path.join(a.tmp, "bridge.err"), "w"))
    pump(3.0)  # the bridge's node found before anything is published
    port = 5300 + os.getpid() % 400
    feed = subprocess.Popen([os.path.join(a.build, "sonar-feed"), "--listen", f"tcp:127.0.0.1:{port}", "--scene", "activity",
                             "--pace", "x8", "--max-seconds", "120"], stderr=open(os.path.join(a.tmp, "feed.err"), "w"))
    live = [os.path.join(a.build, "sonard"), "--sonar", f"tcp:127.0.0.1:{port}", "--range", "15", "--samples", "600",
            "--step", "4", "--lcm", a.lcm, "--quiet"]
    sonard = subprocess.Popen(live + ["--sweeps", "12"], stderr=open(os.path.join(a.tmp, "sonard.err"), "w"))
    while sonard.poll() is None:
        pump(0.2)
    pump(2.0)
    lc.publish("SONAR_DETECTIONS", b"\x00garbage")
    lc.publish("SONAR_STATUS", b"\x00garbage")
    sonard2 = subprocess.Popen(live + ["--sweeps", "2"], stderr=subprocess.DEVNULL)
    while sonard2.poll() is None:
        pump(0.2)
    # Odometry: refused three ways first, then a still pose at 20 Hz while a sonard that reads SONAR_POSE runs.
    odom(frame="map")
    odom(x=math.nan)
    odom(t=time.time() - 60)
    odom(t=time.time() - 120)  # before the last one taken
    pump(0.5)
    n_before = len(lcm["det"])
    sonard3 = subprocess.Popen(live + ["--sweeps", "3", "--pose-lcm", a.lcm],
                               stderr=open(os.path.join(a.tmp, "sonard3.err"), "w"))
    while sonard3.poll() is None:
        odom()
        pump(0.05)
    pump(1.0)
    feed.terminate()
    pump(2.0)
    bridge.terminate()
    bridge.wait(timeout=10)

    det_ok = cloud_ok = n_det = worst = tracked = 0
    for ut, m in lcm["det"].items():
        n_det += 1
        ma, pc = ros["det"].get(ut), ros["cloud"].get(ut)
        marks = [k for k in ma.markers if k.action == Marker.ADD] if ma else None
        if marks is not None and len(marks) == m.count:
            err = max([abs(k.pose.position.x - d.x_m) + abs(k.pose.position.y + d.y_m) for k, d in zip(marks, m.detections)] + [0])
            worst = max(worst, err)
            det_ok += err <= 0.001
        tm = lcm["trk"].get(ut)
        ids = {t.detection: t.id for t in tm.tracks if t.detection >= 0} if tm else {}
        if pc is not None and pc.width == m.count and tm is not None:
            pts = [struct.unpack_from("<7f", pc.data, 28 * i) for i in range(pc.width)]
            cloud_ok += all(abs(p[0] - d.x_m) <= 0.001 and abs(p[1] + d.y_m) <= 0.001 and int(p[6]) == ids.get(i, 0)
                            for i, (p, d) in enumerate(zip(pts, m.detections)))
            tracked += sum(1 for i in range(pc.width) if ids.get(i, 0) > 0)
    check(f"detections: {det_ok} of {n_det} SONAR_DETECTIONS have their MarkerArray, a marker each at the centroid "
          f"within 1 mm (worst {worst * 1000:.3f} mm)", n_det >= 10 and det_ok == n_det)
    check(f"detections/cloud: {cloud_ok} of {n_det} have their PointCloud2, a point each within 1 mm carrying the ID of "
          f"the track that used it ({tracked} points with one)", n_det >= 10 and cloud_ok == n_det and tracked > 0)
    trk_ok = n_trk = n_trails = 0
    for ut, m in lcm["trk"].items():
        n_trk += 1
        ma = ros["trk"].get(ut)
        if ma is not None:
            ids = {k.id // 2 for k in ma.markers if k.action == Marker.ADD and k.ns == "tracks"}
            pos = {t.id: (t.x_m, -t.y_m) for t in m.tracks}
            trails = [k for k in ma.markers if k.ns == "tracks/trail"]
            trk_ok += ids == {t.id for t in m.tracks} and all(
                k.id in pos and 2 <= len(k.points) <= 10 and abs(k.points[-1].x - pos[k.id][0]) <= 0.001
                and abs(k.points[-1].y - pos[k.id][1]) <= 0.001 for k in trails)
            n_trails += len(trails)
    check(f"tracks: {trk_ok} of {n_trk} SONAR_TRACKS have their MarkerArray with the same track IDs, and each of "
          f"{n_trails} trails ends at its track", n_trk >= 10 and trk_ok == n_trk and n_trails > 0)
    alarm_at = min([ut for ut, m in lcm["trk"].items() if any(t.alarms & 1 for t in m.tracks)], default=None)
    errors = [d for d in ros["diag"] if any(s.level == DiagnosticStatus.ERROR and "struggle" in s.message for s in d.status)]
    check(f"a struggle alarm (from sonard's tracks at {alarm_at}) turns /diagnostics to ERROR ({len(errors)} ERROR of "
          f"{len(ros['diag'])})", alarm_at is not None and len(errors) > 0)
    undecoded = [int(v.value) for d in ros["diag"] for s in d.status for v in s.values if v.key == "bridge_undecoded"]
    check(f"two messages that do not decode: counted on /diagnostics ({max(undecoded, default=0)}), the bridge ran on "
          f"({len(undecoded)} diagnostics)", max(undecoded, default=0) >= 2 and sonard2.returncode == 0)
    world = [m for ut, m in sorted(lcm["det"].items())][n_before:]
    placed = [m for m in world if m.world == 1 and abs(m.north_m - 5) < 0.01 and abs(m.east_m + 2) < 0.01
              and abs(m.yaw_deg - 90) < 0.1]
    err3 = open(os.path.join(a.tmp, "sonard3.err")).read()
    check(f"odometry in: sonard's sweeps in the world frame at its pose (north 5, east -2, heading 90): {len(placed)} of "
          f"{len(world)}; sonard exits 0 ({sonard3.returncode})", len(world) >= 3 and len(placed) == len(world)
          and sonard3.returncode == 0 and " 0 refused" in err3)
    odo = {}
    for d in ros["diag"]:
        for st in d.status:
            for v in st.values:
                if v.key.startswith("odometry_"):
                    odo[v.key] = max(odo.get(v.key, 0), int(v.value))
    check(f"bad odometry refused, counted by reason on /diagnostics: {odo}", odo.get("odometry_other_frame") == 1
          and odo.get("odometry_not_finite") == 1 and odo.get("odometry_stamp_backwards") == 1
          and odo.get("odometry_taken", 0) >= 10)
    # The scan: each SONAR_OBSTACLES sector at its ROS angle (counterclockwise: sector k, k x 5 degrees clockwise,
    # is entry (72 - k) % 72), within 1 cm; unknown NaN, clear +inf.
    scan_ok = n_scan = echoes = 0
    for ut, m in lcm["obs"].items():
        sc = ros["scan"].get(ut)
        if sc is None:
            continue
        n_scan += 1
        good, e = scan_matches(m, sc.ranges, sc.angle_increment, sc.range_max)
        scan_ok += good
        echoes += e
    check(f"scan: {scan_ok} of {n_scan} LaserScans (of {len(lcm['obs'])} SONAR_OBSTACLES) hold its sectors within 1 cm, "
          f"NaN unknown, +inf clear ({echoes} echoes)", n_scan >= 0.9 * len(lcm["obs"]) and n_scan >= 20
          and scan_ok == n_scan and echoes > 0)
    # The fan: along the axis of the beam an image is stamped with, half way out, that beam's middle samples.
    img_ok = n_img = 0
    for im in ros["img"]:
        b = lcm["beam"].get(stamp_us(im.header))
        if b is None or im.encoding != "mono8" or im.width != 400 or im.height != 400:
            continue
        n_img += 1
        th, c, r = math.radians(b.angle * 0.9), 199.5, 100.0
        px = im.data[int(round(c - r * math.cos(th))) * im.step + int(round(c + r * math.sin(th)))]
        k = b.number_of_samples // 2
        near = bytes(b.samples)[max(0, k - 4):k + 5]
        img_ok += min(near) <= px <= max(near)
    check(f"image: {len(ros['img'])} mono8 fans; {img_ok} of {n_img} stamped with a beam hold it along its axis",
          n_img >= 5 and img_ok == n_img)
    lat = [ros["t_det"][ut] - lcm["t_det"][ut] for ut in lcm["t_det"] if ut in ros["t_det"]]
    if lat:
        print(f"latency LCM -> ROS of a sweep's detections: median {statistics.median(lat) * 1000:.1f} ms, "
              f"max {max(lat) * 1000:.1f} ms over {len(lat)}")
    check("every sweep's detections on ROS within 50 ms of their LCM message", bool(lat) and max(lat) <= 0.050)
    node.destroy_node()
    rclpy.shutdown()
    bag_checks(a)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
