#!/usr/bin/env python3
"""pose_log.py -- writes an LCM log of sonar.pose_t on SONAR_POSE (from a pose CSV, or one constant pose),
timed from now: `sonard --pose-lcm file://LOG?mode=r` then reads it as a vehicle's LCM would send it.

  pose_log.py TYPES_DIR OUT.lcm --csv veh.pose.csv      the CSV's path, shifted to start now
  pose_log.py TYPES_DIR OUT.lcm --still N E YAW --seconds S --hz H
"""
import argparse
import csv
import struct
import sys
import time

SYNC = 0xEDA1DA01


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("types", help="the generated Python LCM types (BUILD/lcm/python)")
    ap.add_argument("out")
    ap.add_argument("--csv")
    ap.add_argument("--still", nargs=3, type=float, metavar=("NORTH", "EAST", "YAW"))
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--hz", type=float, default=20.0)
    ap.add_argument("--channel", default="SONAR_POSE")
    a = ap.parse_args()
    sys.path.insert(0, a.types)
    from sonar.pose_t import pose_t  # noqa: E402 (generated at build time)
    t0 = int(time.time() * 1e6)
    rows = []
    if a.csv:
        with open(a.csv) as f:
            r = list(csv.DictReader(f))
        first = int(r[0]["utime_us"])
        rows = [(t0 + int(x["utime_us"]) - first, float(x["north_m"]), float(x["east_m"]), float(x["yaw_deg"])) for x in r]
    elif a.still:
        n, e, y = a.still
        rows = [(t0 + int(k * 1e6 / a.hz), n, e, y) for k in range(int(a.seconds * a.hz))]
    else:
        ap.error("give --csv or --still")
    ch = a.channel.encode()
    with open(a.out, "wb") as f:
        for k, (t, n, e, y) in enumerate(rows):
            p = pose_t()
            p.utime, p.north_m, p.east_m, p.yaw_deg = t, n, e, y
            data = p.encode()
            f.write(struct.pack(">IqqII", SYNC, k, t, len(ch), len(data)) + ch + data)
    return 0


if __name__ == "__main__":
    sys.exit(main())
