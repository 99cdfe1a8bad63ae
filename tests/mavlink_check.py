#!/usr/bin/env python3
"""mavlink_check.py -- plays a vehicle's autopilot to sonard's --mavlink udpin endpoint and decodes,
with pymavlink's own parser and CRCs, everything sonard sends back; writes a JSON report.

The autopilot (system 1, component 1) sends HEARTBEAT at 1 Hz and ATTITUDE + LOCAL_POSITION_NED at
20 Hz for a sonar that stands still, heading north; once a second it also sends what sonard must
ignore and count: a message with a broken CRC, one of a dialect sonard does not have, random bytes,
and an ATTITUDE from another system (sysid 7). Loopback only, bounded by --seconds.

Report: message counts; OBSTACLE_DISTANCE and HEARTBEAT rates; the fields of every
OBSTACLE_DISTANCE; the last one's sectors against the simulated scene (walls and objects from
sonar-sim's truth: the nearest obstacle inside each 5-degree sector); the OBSTACLE_DISTANCE_3D bursts.
"""
import argparse
import json
import math
import random
import socket
import struct
import sys
import time

from pymavlink.dialects.v20 import ardupilotmega as apm

from ardupilot_model import Proximity
from stallwatch import LOOP_S, Watch, overlap
from sim_geom import ray_segment


def nearest_in_arc(centre, width, walls, objects, rmax, by_centre=False):
    """The nearest wall or object surface within centre +- width / 2 degrees, metres. by_centre: an
    object counts in the arc holding its centre only (a face's obstacle), not in every arc it reaches."""
    best = None
    steps = int(width * 10)
    for i in range(steps + 1):
        th = math.radians(centre - width / 2 + 0.1 * i)
        ux, uy = math.cos(th), math.sin(th)
        for w in walls:
            t = ray_segment(ux, uy, *w)
            if t is not None and (best is None or t < best):
                best = t
    lo, hi = math.radians(centre - width / 2), math.radians(centre + width / 2)
    for o in objects:
        d = math.hypot(o["x"], o["y"])
        phi = math.atan2(o["y"], o["x"])
        half = math.asin(min(1.0, o["radius"] / d))
        mid = (lo + hi) / 2
        gap = abs((phi - mid + math.pi) % (2 * math.pi) - math.pi)
        if gap <= (hi - lo) / 2 + (0.0 if by_centre else half):
            best = d - o["radius"] if best is None else min(best, d - o["radius"])
    return best if best is not None and best <= rmax else None


SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)  # Linux's value; Python names it from 3.12 on
def arrival(anc):
    """The kernel's receive time (SO_TIMESTAMPNS) of a datagram, epoch seconds; now when it gave none."""
    for level, kind, data in anc:
        if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS and len(data) >= 16:
            sec, nsec = struct.unpack("qq", data[:16])
            return sec + nsec * 1e-9
    return time.time()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--port", type=int, required=True)
    ap.add_argument("--seconds", type=float, required=True)
    ap.add_argument("--truth", help="sonar-sim truth JSON of the scene served (walls, objects)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--sysid", type=int, default=1, help="the autopilot's system id")
    ap.add_argument("--router", type=int, metavar="PORT",
                    help="also a router: the autopilot (sonar-feed) sends to this port, everything is passed both ways, "
                         "and its poses are kept, so each face is scored from where the vehicle is (a moving vehicle)")
    ap.add_argument("--od-log", metavar="FILE",
                    help="every OBSTACLE_DISTANCE as a JSON line: receive time (s since the epoch), min, max, offset, distances")
    ap.add_argument("--listen-only", action="store_true",
                    help="no autopilot: only a ground station's HEARTBEAT (sysid 255), to be answered")
    a = ap.parse_args()
    dest = ("127.0.0.1", a.port)
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.setblocking(False)
    # Each datagram's arrival as the kernel stamped it: a gap between messages is sonard's, not this checker's wake.
    s.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
    ours = apm.MAVLink(None, srcSystem=255 if a.listen_only else a.sysid, srcComponent=190 if a.listen_only else 1)
    gcs = apm.MAVLink(None, srcSystem=255, srcComponent=190)
    ardupilot = Proximity()
    zeros, od_abs = 0, []
    other = apm.MAVLink(None, srcSystem=7, srcComponent=1)
    rx = apm.MAVLink(None)
    rx.robust_parsing = True
    rng = random.Random(1)
    router, feed_addr, rrx = None, None, apm.MAVLink(None)
    rrx.robust_parsing = True
    pose = None        # (north, east, yaw degrees) of the vehicle, from the autopilot's messages through the router
    pos = (0.0, 0.0)
    snaps = []         # (t, pose, ArduPilot's faces) once a second
    next_snap = None
    if a.router:
        router = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        router.bind(("127.0.0.1", a.router))
        router.setblocking(False)
    od_log = open(a.od_log, "w", buffering=1) if a.od_log else None
    t0 = time.time()
    next_hb = next_pose = next_junk = t0
    counts, bad = {}, 0
    od, hb, od3d = [], [], []
    watch = Watch()    # this loop's own lateness: the machine was paused, or busy
    while time.time() - t0 < a.seconds:
        now = time.time()
        watch.tick()
        ms = int((now - t0) * 1000)
        if now >= next_hb:
            if a.listen_only:
                s.sendto(ours.heartbeat_encode(apm.MAV_TYPE_GCS, apm.MAV_AUTOPILOT_INVALID, 0, 0,
                                               apm.MAV_STATE_ACTIVE).pack(ours), dest)
            else:
                s.sendto(ours.heartbeat_encode(apm.MAV_TYPE_SUBMARINE, apm.MAV_AUTOPILOT_ARDUPILOTMEGA, 0, 0,
                                               apm.MAV_STATE_ACTIVE).pack(ours), dest)
            next_hb += 1.0
        if now >= next_pose and a.listen_only:
            next_pose = next_junk = now + 3600
        if now >= next_pose:
            s.sendto(ours.attitude_encode(ms, 0, 0, 0.0, 0, 0, 0).pack(ours), dest)
            s.sendto(ours.local_position_ned_encode(ms, 0.0, 0.0, 0.0, 0, 0, 0).pack(ours), dest)
            next_pose += 0.05
        if now >= next_junk:
            good = bytearray(ours.attitude_encode(ms, 0, 0, 1.0, 0, 0, 0).pack(ours))
            good[-1] ^= 0x5A  # a broken CRC
            s.sendto(bytes(good), dest)
            payload = bytes(rng.randrange(256) for _ in range(12))
            # MAVLink 2 framing of message id 0xABCDE, in no dialect sonard knows
            s.sendto(struct.pack("<BBBBBBB", 0xFD, len(payload), 0, 0, 0, 9, 9) + bytes([0xDE, 0xBC, 0x0A]) +
                     payload + b"\x12\x34", dest)
            s.sendto(bytes(rng.randrange(256) for _ in range(40)), dest)
            s.sendto(other.attitude_encode(ms, 0, 0, 1.57, 0, 0, 0).pack(other), dest)
            # a second autopilot on the link, a ground station, an answer to a command sonard never sent
            s.sendto(other.heartbeat_encode(apm.MAV_TYPE_QUADROTOR, apm.MAV_AUTOPILOT_ARDUPILOTMEGA, 0, 0,
                                            apm.MAV_STATE_ACTIVE).pack(other), dest)
            s.sendto(gcs.heartbeat_encode(apm.MAV_TYPE_GCS, apm.MAV_AUTOPILOT_INVALID, 0, 0,
                                          apm.MAV_STATE_ACTIVE).pack(gcs), dest)
            s.sendto(ours.command_ack_encode(apm.MAV_CMD_COMPONENT_ARM_DISARM, 0).pack(ours), dest)
            next_junk += 1.0
        if router is not None:
            try:
                while True:
                    data, feed_addr = router.recvfrom(4096)
                    s.sendto(data, dest)
                    for m in rrx.parse_buffer(data) or []:
                        if m.get_type() == "LOCAL_POSITION_NED":
                            pos = (m.x, m.y)
                        elif m.get_type() == "ATTITUDE":
                            pose = (pos[0], pos[1], math.degrees(m.yaw) % 360.0)
            except BlockingIOError:
                pass
            if pose is not None and ardupilot.last_msg is not None and now - t0 > 15.0 and (next_snap is None or now >= next_snap):
                snaps.append((now - t0, pose, ardupilot.distances(now - t0)))
                next_snap = now + 1.0
        try:
            while True:
                data, anc, _, _ = s.recvmsg(4096, socket.CMSG_SPACE(16))
                if router is not None and feed_addr is not None:
                    router.sendto(data, feed_addr)
                got = arrival(anc) - t0
                for m in rx.parse_buffer(data) or []:
                    name = m.get_type()
                    if name == "BAD_DATA":
                        bad += 1
                        continue
                    counts[name] = counts.get(name, 0) + 1
                    if name == "OBSTACLE_DISTANCE":
                        ardupilot.obstacle_distance(m, got)
                        zeros += sum(1 for x in m.distances if x == 0)
                        od_abs.append(time.time())
                        if od_log is not None:
                            od_log.write(json.dumps({"t": od_abs[-1], "min": m.min_distance, "max": m.max_distance,
                                                     "offset": m.angle_offset, "distances": list(m.distances)}) + "\n")
                        od.append({"t": got, "distances": list(m.distances), "min": m.min_distance, "max": m.max_distance,
                                   "increment": m.increment, "increment_f": m.increment_f, "angle_offset": m.angle_offset,
                                   "frame": m.frame, "sensor_type": m.sensor_type, "sysid": m.get_srcSystem(),
                                   "compid": m.get_srcComponent()})
                    elif name == "HEARTBEAT":
                        hb.append({"t": got, "type": m.type, "autopilot": m.autopilot, "sysid": m.get_srcSystem(),
                                   "compid": m.get_srcComponent()})
                    elif name == "OBSTACLE_DISTANCE_3D":
                        od3d.append({"t": got, "time_boot_ms": m.time_boot_ms, "id": m.obstacle_id, "x": m.x, "y": m.y,
                                     "z": m.z, "frame": m.frame})
        except BlockingIOError:
            pass
        time.sleep(LOOP_S)
    stalls = [(x - t0, y - t0) for x, y in watch.stalls]
    rep = {"stalls": [[round(x, 3), round(y, 3)] for x, y in stalls], "stalled_s": sum(y - x for x, y in stalls),
           "counts": counts, "bad_data": bad, "od_n": len(od), "hb": hb, "od3d": od3d, "zero_distances": zeros,
           "od_last_abs": od_abs[-1] if od_abs else None}
    if len(od) > 2:
        rep["od_rate_hz"] = (len(od) - 1) / (od[-1]["t"] - od[0]["t"])
        gaps = [b["t"] - a_["t"] for a_, b in zip(od, od[1:])]
        rep["od_max_gap_s"] = max(gaps)
        # Each gap less the stalls this checker saw within it: what sonard was late by itself.
        own = [b["t"] - a_["t"] - overlap(stalls, a_["t"], b["t"]) for a_, b in zip(od, od[1:])]
        rep["od_max_gap_own_s"] = max(own)
        rep["od_p99_gap_s"] = sorted(gaps)[min(len(gaps) - 1, int(0.99 * len(gaps)))]
        rep["od_rate_unstalled_hz"] = (len(od) - 1) / (od[-1]["t"] - od[0]["t"] - overlap(stalls, od[0]["t"], od[-1]["t"]))
        rep["od_fields"] = sorted({json.dumps({k: v for k, v in o.items() if k not in ("t", "distances")},
                                              sort_keys=True) for o in od})
        rep["od_last"] = od[-1]["distances"]
    if len(hb) > 2:
        rep["hb_rate_hz"] = (len(hb) - 1) / (hb[-1]["t"] - hb[0]["t"])
    if a.truth and od:
        tr = json.load(open(a.truth))
        walls = tr.get("walls", [])
        # Objects that stand still through the truth (a moving one was elsewhere when its sector was scanned).
        where = {}
        for sw in tr["sweeps"]:
            for o in sw["objects"]:
                where.setdefault(o["id"], set()).add((round(o["x"], 2), round(o["y"], 2)))
        objs = [o for o in tr["sweeps"][-1]["objects"] if len(where[o["id"]]) == 1]
        last = od[-1]
        rmax = last["max"] / 100.0
        off = last["angle_offset"]
        # What ArduPilot holds, face by face, after the last message, against the nearest surface in each face.
        faces = []
        for f, got in enumerate(ardupilot.distances(last["t"])):
            want = nearest_in_arc(45.0 * f, 45.0, walls, objs, rmax, by_centre=True)
            faces.append({"face": f, "got": got, "want": want,
                          "err": None if got is None or want is None else got - want})
        rep["faces"] = faces
        errs = []
        for k, d in enumerate(last["distances"]):
            want = nearest_in_arc(5 * k + off, 5.0, walls, objs, rmax)
            if d == 65535:
                continue
            got = None if d == last["max"] + 1 else d / 100.0
            errs.append({"sector": k, "centre": 5 * k + off, "got": got, "want": want,
                         "err": None if got is None or want is None else got - want})
        rep["sectors"] = errs
    if a.truth and snaps:
        # A moving vehicle: the walls and the posts (world) brought into the body frame at each snapshot's pose.
        tr = json.load(open(a.truth))
        where = {}
        for sw in tr["sweeps"]:
            for o in sw["objects"]:
                where.setdefault(o["id"], set()).add((round(o["x"], 2), round(o["y"], 2)))
        still = [o for o in tr["sweeps"][-1]["objects"] if len(where[o["id"]]) == 1]
        rmax = od[-1]["max"] / 100.0 if od else 15.0
        errs = []
        for t, (n0, e0, yaw), got in snaps:
            c, s_ = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
            body = lambda n, e: (c * (n - n0) + s_ * (e - e0), -s_ * (n - n0) + c * (e - e0))  # noqa: E731
            walls = [body(w[0], w[1]) + body(w[2], w[3]) for w in tr.get("walls", [])]
            objs = [dict(o, x=body(o["x"], o["y"])[0], y=body(o["x"], o["y"])[1]) for o in still]
            for f in range(8):
                want = nearest_in_arc(45.0 * f, 45.0, walls, objs, rmax, by_centre=True)
                if got[f] is not None and want is not None:
                    errs.append(got[f] - want)
        rep["moving_faces"] = {"snapshots": len(snaps), "errors": errs}
    json.dump(rep, open(a.out, "w"), indent=1)
    print(f"mavlink_check: {sum(counts.values())} messages ({', '.join(f'{k} {v}' for k, v in sorted(counts.items()))}), "
          f"{bad} bad")
    return 0


if __name__ == "__main__":
    sys.exit(main())
