#!/usr/bin/env python3
"""brping_check.py -- Blue Robotics' own Python client (bluerobotics-ping) against sonar-feed over UDP.

Shows that sonar-feed speaks the real Ping Protocol, not only sonard's dialect: brping must
initialise (protocol_version, then device_data through general_request) and read a full
400-gradian sweep with transmitAngle. Exits 1 on any missing or wrong reply.
"""
import argparse
import sys
import time

from brping import Ping360


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int, required=True)
    a = ap.parse_args()
    p = Ping360()
    p.connect_udp(a.host, a.port)
    if not p.initialize():
        sys.exit("brping: initialize() failed: no protocol_version or device_data reply")
    good, t0 = 0, time.time()
    for angle in range(400):
        r = p.transmitAngle(angle)
        if r is None:
            sys.exit(f"brping: no reply for angle {angle}")
        if r.name != "device_data" or r.angle != angle or len(r.data) != r.number_of_samples or r.number_of_samples == 0:
            sys.exit(f"brping: bad reply for angle {angle}: {r.name} angle {getattr(r, 'angle', '?')}")
        good += 1
    p.control_motor_off()
    print(f"brping {getattr(sys.modules['brping'], '__version__', '0.2.x')}: initialised, read {good}/400 beams of "
          f"{r.number_of_samples} samples with transmitAngle in {time.time() - t0:.1f} s")


if __name__ == "__main__":
    main()
