#!/usr/bin/env python3
"""lcm_udpm_check.py -- the view's plain-Python LCM receiver against LCM's own publisher on a private udpm bus:
short and fragmented messages byte-equal, channels matched as LCM does, malformed datagrams counted.
Run inside `unshare -rn` with lo up and 224.0.0.0/4 routed to it (tests/view.sh). Prints [  PASS  ]/[  FAIL  ] lines."""
import os
import select
import struct
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools", "view"))
import lcm  # noqa: E402  (LCM's binding, the reference publisher)
from lcm_udpm import Udpm  # noqa: E402

URL = "udpm://239.255.76.67:7667?ttl=0"
ok = True


def check(cond, what):
    global ok
    print(f"[  {'PASS' if cond else 'FAIL'}  ] {what}")
    ok &= bool(cond)


rx = Udpm(URL)
got = []
rx.subscribe("SONAR_BEAM", lambda c, d: got.append((c, d)))
rx.subscribe("X.*", lambda c, d: got.append((c, d)))
pub = lcm.LCM(URL)
sent = [("SONAR_BEAM", bytes(range(256)) * 5), ("XYZ", b"\x01"), ("SONAR_BEAMS", b"not this one"),
        ("SONAR_BEAM", os.urandom(200000)), ("XL", os.urandom(70000))]
for c, d in sent:  # one at a time: a 200 kB message alone nearly fills a socket's default buffer
    n = len(got)
    pub.publish(c, d)
    deadline = time.time() + 1
    while len(got) == n and time.time() < deadline:
        if select.select([rx], [], [], 0.1)[0]:
            rx.handle()
want = [(c, d) for c, d in sent if c != "SONAR_BEAMS"]
check(got == want, f"LCM's own short and fragmented messages (1280 B, 1 B, 200 000 B, 70 000 B) arrive byte-equal, "
      f"channels matched whole: {len(got)} of {len(want)}")
bad0 = rx.bad
rx.feed(b"LC0", ("1.2.3.4", 1))                                              # too short
rx.feed(struct.pack(">II", 0x12345678, 1) + b"C\0x", ("1.2.3.4", 1))        # not LCM
rx.feed(struct.pack(">II", 0x4C433032, 1) + b"no terminator", ("1.2.3.4", 1))
rx.feed(struct.pack(">IIIIHH", 0x4C433033, 9, 100, 50, 1, 2) + b"x" * 50, ("1.2.3.4", 1))   # start lost
rx.feed(struct.pack(">IIIIHH", 0x4C433033, 9, 1 << 30, 0, 0, 2) + b"C\0", ("1.2.3.4", 1))   # too big
rx.feed(struct.pack(">IIIIHH", 0x4C433033, 9, 10, 0, 0, 2) + b"XA\0" + b"y" * 20, ("1.2.3.4", 1))  # past its size
check(rx.bad - bad0 == 6 and len(got) == len(want), f"six malformed datagrams counted and skipped: {rx.bad - bad0}")
sys.exit(0 if ok else 1)
