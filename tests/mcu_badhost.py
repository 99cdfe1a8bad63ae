#!/usr/bin/env python3
"""mcu_badhost.py -- plays a bad host to the co-processor's UART1 (QEMU's TCP server): garbage, a truncated frame, a
corrupt frame and an out-of-range configuration, then a good one. The firmware must answer the bad configuration with
the failing field, keep its settings, and accept the good one. Prints one line per check; exits 1 on a failure.

Usage: mcu_badhost.py PORT --types BUILD/lcm/python
"""
import argparse
import os
import socket
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)) + "/../tools/data")
import cpframe  # noqa: E402


def replies(sock, seconds):
    """Frames on channel 17 within seconds, and the status frames seen."""
    data, end, got, status = b"", time.time() + seconds, [], 0
    sock.settimeout(0.2)
    while time.time() < end:
        try:
            chunk = sock.recv(65536)
            if not chunk:
                break
            data += chunk
        except socket.timeout:
            pass
        got = [p.decode(errors="replace") for ch, p in cpframe.frames(data) if ch == 17]
        status = sum(1 for ch, _ in cpframe.frames(data) if ch == 2)
        if got:
            break
    return got, status


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("port", type=int)
    ap.add_argument("--types", required=True)
    a = ap.parse_args()
    sys.path.insert(0, a.types)
    from sonar import config_t
    c = config_t()
    c.range_m, c.speed_of_sound, c.samples, c.gain, c.frequency = 12.0, 1500.0, 200, 0, 750
    c.start_angle, c.stop_angle, c.step, c.full_circle, c.use_auto = 100, 300, 2, False, False
    c.median, c.median2d, c.max_step, c.bg_mode, c.bg_warmup, c.bg_step, c.bg_margin = 5, 0, 20, 1, 2, 1, 8
    c.threshold_k, c.min_threshold, c.max_clusters, c.iterations, c.join_beams = 3.0, 16, 8, 10, 9  # 9: out of range
    c.min_points, c.join_m, c.track_points, c.beam_every = 20, 0.15, 10, 0
    bad = c.encode()
    c.join_beams = 2
    good = c.encode()
    ok = True
    s = socket.create_connection(("127.0.0.1", a.port), timeout=5)
    # Garbage, a truncated frame and a corrupt one first: all must be dropped without a reply.
    frame = cpframe.encode(16, good)
    corrupt = bytearray(frame)
    corrupt[20] ^= 0x55
    s.sendall(os.urandom(300) + frame[:40] + bytes(corrupt))
    got, _ = replies(s, 3.0)
    print(("PASS" if not got else "FAIL") + ": garbage, a truncated and a corrupt configuration frame get no reply", got)
    ok &= not got
    s.sendall(cpframe.encode(16, bad))
    got, _ = replies(s, 5.0)
    named = bool(got) and got[0].startswith("error:") and "join_beams: 1..8" in got[0]
    print(("PASS" if named else "FAIL") + ": an out-of-range configuration is refused, naming the field:", got)
    ok &= named
    s.sendall(cpframe.encode(16, good))
    got, _ = replies(s, 5.0)
    print(("PASS" if got == ["ok"] else "FAIL") + ": then a good one is accepted:", got)
    ok &= got == ["ok"]
    # A host that goes silent: the firmware keeps sending status frames (QEMU buffers them in the socket).
    time.sleep(2.5)
    _, status = replies(s, 1.0)
    print(("PASS" if status >= 2 else "FAIL") + f": after 2.5 s of a silent host, {status} status frames were waiting")
    ok &= status >= 2
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
