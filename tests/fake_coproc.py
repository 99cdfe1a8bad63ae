#!/usr/bin/env python3
"""fake_coproc.py -- a stand-in co-processor on 127.0.0.1:PORT (bounded: 20 s). By default it refuses every
configuration: it answers the first configuration frame with "error: ...", then keeps the link open. With
--accept LOG it answers "ok" to every configuration frame and writes each one's detector settings to LOG as a JSON
line (decoded with the generated Python types in --types DIR), until the link closes.

Usage: fake_coproc.py PORT [--accept LOG --types DIR]
"""
import argparse
import json
import os
import socket
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)) + "/../tools/data")
import cpframe  # noqa: E402

CONFIG, REPLY = 16, 17

ap = argparse.ArgumentParser()
ap.add_argument("port", type=int)
ap.add_argument("--accept", metavar="LOG")
ap.add_argument("--types", metavar="DIR")
a = ap.parse_args()
if a.accept:
    sys.path.insert(0, a.types)
    from sonar import config_t  # noqa: E402

srv = socket.socket()
srv.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
srv.bind(("127.0.0.1", a.port))
srv.listen(1)
srv.settimeout(20)
c, _ = srv.accept()
c.settimeout(1.0)
data, end, used = b"", time.time() + 20, 0
while time.time() < end:
    try:
        chunk = c.recv(4096)
        if not chunk:
            break
        data += chunk
    except socket.timeout:
        continue
    frames = [p for ch, p in cpframe.frames(data) if ch == CONFIG]
    if not a.accept:
        if frames:
            c.sendall(cpframe.encode(REPLY, b"error: detector.track_points: 1..65535 when track_m is set"))
            break
        continue
    for p in frames[used:]:
        m = config_t.decode(p)
        with open(a.accept, "a") as f:
            f.write(json.dumps({"min_points": m.min_points, "angle_offset": m.angle_offset, "range_m": m.range_m}) + "\n")
        c.sendall(cpframe.encode(REPLY, b"ok"))
    used = len(frames)
if not a.accept:
    time.sleep(3)
