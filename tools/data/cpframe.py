#!/usr/bin/env python3
"""cpframe.py -- decodes a capture of the co-processor's host link (docs/coprocessor.md): one line per frame.

Usage: cpframe.py CAPTURE --types BUILD/lcm/python [--last-status]
"""
import argparse
import binascii
import struct
import sys


def frames(data):
    """Yields (channel, payload) of every frame with a good CRC; resyncs byte by byte like the C parser."""
    i = 0
    while i + 9 <= len(data):
        if data[i] != 0xA5 or data[i + 1] != 0x5C:
            i += 1
            continue
        ch, n = data[i + 2], struct.unpack_from("<H", data, i + 3)[0]
        if n > 4096 or i + 9 + n > len(data):
            i += 1
            continue
        crc = struct.unpack_from("<I", data, i + 5 + n)[0]
        if binascii.crc32(data[i + 2:i + 5 + n]) & 0xFFFFFFFF != crc:
            i += 1
            continue
        yield ch, data[i + 5:i + 5 + n]
        i += 9 + n


def encode(channel, payload):
    """One frame: sync, channel, length, payload, CRC-32 of channel + length + payload."""
    body = bytes([channel]) + struct.pack("<H", len(payload)) + payload
    return b"\xA5\x5C" + body + struct.pack("<I", binascii.crc32(body) & 0xFFFFFFFF)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("capture")
    ap.add_argument("--types", required=True)
    ap.add_argument("--last-status", action="store_true")
    a = ap.parse_args()
    sys.path.insert(0, a.types)
    from sonar import beam_t, detections_t, status_t
    last = None
    for ch, p in frames(open(a.capture, "rb").read()):
        if ch == 2:
            last = status_t.decode(p)
            if not a.last_status:
                print("status", {s: getattr(last, s) for s in status_t.__slots__ if s != "link"})
        elif ch == 1 and not a.last_status:
            d = detections_t.decode(p)
            print("detections sweep", d.sweep, "beams", d.beams, "count", d.count)
        elif ch == 3 and not a.last_status:
            b = beam_t.decode(p)
            print("beam", b.angle, b.number_of_samples)
        elif ch == 17 and not a.last_status:
            print("reply", p.decode(errors="replace"))
    if a.last_status and last is not None:
        print({s: getattr(last, s) for s in status_t.__slots__ if s != "link"})


if __name__ == "__main__":
    main()
