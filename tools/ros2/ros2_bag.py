"""ros2_bag.py -- sonard's LCM log as a ROS 2 bag (MCAP, CDR, the ros2msg schemas): the bridge's topics
(sonard_ros2.py's Bridge, fed from the log instead of the bus), written by mcap-ros2-support, for lcm2mcap --ros2.

A ROS 2 MCAP names each schema by its type (sensor_msgs/msg/LaserScan) and holds its full definition: the type's
.msg text, then each type it uses after a line of 80 '=' and "MSG: pkg/Type". The texts are read from the ROS 2 in
use (.venv-ros2's share/, or a sourced distribution's AMENT_PREFIX_PATH), so a bag carries the definitions its
messages were serialised with. Each message's log time is its header's stamp (sonard's utime).
"""
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SEP = "=" * 80
PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32",
              "int64", "uint64", "string", "wstring"}


class BagError(Exception):
    pass


def share_dirs():
    dirs = [os.path.join(p, "share") for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return dirs + [os.path.join(sys.prefix, "share")]


def msg_text(pkg, name):
    for d in share_dirs():
        path = os.path.join(d, pkg, "msg", name + ".msg")
        if os.path.isfile(path):
            with open(path) as f:
                return f.read()
    raise BagError(f"no {pkg}/msg/{name}.msg under {', '.join(share_dirs())}: is this ROS 2 installed whole?")


def used_types(pkg, text):
    """The message types a .msg text's fields use, in order: (pkg, name)."""
    out = []
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        parts = line.split()
        if len(parts) < 2 or "=" in line[len(parts[0]):]:
            continue  # blank, or a constant (NAME=value; the type's own '=' is a bound, as in string<=8)
        base = re.sub(r"<=\d+$", "", re.sub(r"\[[^\]]*\]$", "", parts[0]))
        if base in PRIMITIVES:
            continue
        bits = base.split("/")
        out.append((bits[0], bits[-1]) if len(bits) > 1 else (pkg, bits[0]))
    return out


def msgdef(pkg, name):
    """The full definition of pkg/msg/name for an MCAP schema: its text, then every type it uses, depth first, once."""
    seen, parts = set(), []

    def add(p, n, top):
        if (p, n) in seen:
            return
        seen.add((p, n))
        text = msg_text(p, n)
        parts.append(text.rstrip("\n") if top else f"{SEP}\nMSG: {p}/{n}\n{text.rstrip()}")
        for q, m in used_types(p, text):
            add(q, m, False)
    add(pkg, name, True)
    return "\n".join(parts) + "\n"


def type_of(cls):
    """(pkg, name) of an rclpy message class: sensor_msgs.msg._laser_scan.LaserScan -> (sensor_msgs, LaserScan)."""
    return cls.__module__.split(".")[0], cls.__name__


class BagNode:
    """What Bridge needs of a node: create_publisher. Each publisher writes into the bag under the namespace."""

    def __init__(self, writer, ns):
        self.writer, self.ns, self.schemas, self.counts = writer, ns.rstrip("/"), {}, {}

    def create_publisher(self, cls, topic, qos):
        full = topic if topic.startswith("/") else f"{self.ns}/{topic}"
        key = type_of(cls)
        if key not in self.schemas:
            self.schemas[key] = self.writer.register_msgdef(f"{key[0]}/msg/{key[1]}", msgdef(*key))
        return BagPub(self, full, self.schemas[key])


class BagPub:
    def __init__(self, node, topic, schema):
        self.node, self.topic, self.schema = node, topic, schema

    def publish(self, msg):
        h = msg.header if hasattr(msg, "header") else msg.markers[0].header  # a MarkerArray: its DELETEALL's
        t = h.stamp.sec * 1000000000 + h.stamp.nanosec
        self.node.writer.write_message(self.topic, self.schema, msg, log_time=t, publish_time=t)
        self.node.counts[self.topic] = self.node.counts.get(self.topic, 0) + 1


def convert(events, out_path, types_dir, prefix, ns, report):
    """events: (utime, channel, data) from an LCM log. Writes the bag; returns (counts per topic, LCM messages not
    read per channel, the log's error or None)."""
    sys.path.insert(0, HERE)
    from mcap_ros2.writer import Writer
    import sonard_ros2
    params = {k: v[0] for k, v in sonard_ros2.PARAMS.items()}
    with open(out_path, "wb") as f:
        w = Writer(f)
        node = BagNode(w, ns)
        bridge = sonard_ros2.Bridge(node, params)
        table = sonard_ros2.handlers(types_dir, prefix, bridge)
        skipped, error = {}, None
        try:
            for _utime, channel, data in events:
                h = table.get(channel)
                if h is None:
                    skipped[channel] = skipped.get(channel, 0) + 1
                else:
                    h(channel, data)
        except Exception as e:  # the log's own error (truncated, corrupt): what came before it is in the bag
            if e.__class__.__name__ != "LogError":
                raise
            error = str(e)
        bridge.flush_clouds(1 << 62)  # the last sweeps' clouds, with whatever tracks came
        w.finish()
    for channel, n in bridge.bad.items():
        report(f"lcm2mcap --ros2: {n} {channel} messages did not decode, skipped")
    return node.counts, skipped, error
