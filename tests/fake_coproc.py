#!/usr/bin/env python3
"""fake_coproc.py -- a co-processor that refuses every configuration: listens on 127.0.0.1:PORT, answers the first
configuration frame with "error: ...", then keeps the link open (bounded: 20 s).

Usage: fake_coproc.py PORT
"""
import os
import socket
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)) + "/../tools/data")
import cpframe  # noqa: E402

srv = socket.socket()
srv.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
srv.bind(("127.0.0.1", int(sys.argv[1])))
srv.listen(1)
srv.settimeout(20)
c, _ = srv.accept()
c.settimeout(1.0)
data, end = b"", time.time() + 20
while time.time() < end:
    try:
        chunk = c.recv(4096)
        if not chunk:
            break
        data += chunk
    except socket.timeout:
        continue
    if any(ch == 16 for ch, _ in cpframe.frames(data)):
        c.sendall(cpframe.encode(17, b"error: detector.track_points: 1..65535 when track_m is set"))
        break
time.sleep(3)
