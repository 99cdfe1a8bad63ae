#!/usr/bin/env python3
"""make_pvbin.py -- builds a genuine Ping Viewer sensor log (.bin) from the real beams of the pingviewer_noah dump.

Qt QDataStream layout (big-endian): QString header "PingViewer sensor log file" (UTF-16BE), int32
version 1, five QStrings (hash, date, tag, OS name, OS version), int32 family 1, int32 type 2;
then records {QString "hh:mm:ss.zzz", QByteArray chunk}. The beams are re-encoded as Ping
frames (src 2, dst 0) and the byte stream is cut into chunks that do not line up with frames,
with junk before the first frame, as a serial readAll() delivers them. Writes FILE and prints
how many beams it holds (the dump's inconsistent record is left out: it cannot be re-encoded).
Usage: make_pvbin.py DUMP OUT.bin [--utf8]
"""
import random
import struct
import sys


def qstring(s, utf8=False):
    b = s.encode("utf-8" if utf8 else "utf-16-be")
    return struct.pack(">I", len(b)) + b


def frame(mid, payload, src=2):
    h = b"BR" + struct.pack("<HHBB", len(payload), mid, src, 0)
    body = h + payload
    return body + struct.pack("<H", sum(body) & 0xFFFF)


def main():
    dump, out = sys.argv[1], sys.argv[2]
    utf8 = "--utf8" in sys.argv
    sys.path.insert(0, sys.argv[sys.argv.index("--tools") + 1] if "--tools" in sys.argv else ".")
    import parse_pingviewer_decoded as p
    rows = [r for r in p.rows(dump) if r.get("consistent") and r["message_id"] == 2300]
    stream, times = b"\x00\x13garbage\x7fBB", []
    for r in rows:
        pl = struct.pack("<BBHHHHHH", r["mode"], r["gain_setting"], r["angle"], r["transmit_duration"], r["sample_period"],
                         r["transmit_frequency"], r["number_of_samples"], len(r["samples"])) + r["samples"]
        times.append((len(stream), r["t"]))
        stream += frame(2300, pl)
    rnd = random.Random(7)
    data = qstring("PingViewer sensor log file", utf8) + struct.pack(">i", 1)
    for s in ("36168c2", "2022-03-07T11:50:10-03:00", "", "Windows 10 Version 2009", "10"):
        data += qstring(s, utf8)
    data += struct.pack(">ii", 1, 2)
    off, k = 0, 0
    while off < len(stream):
        n = rnd.randint(1, 3000)
        while k + 1 < len(times) and times[k + 1][0] <= off:
            k += 1
        t = times[k][1]
        ms = int(round(t * 1000))
        stamp = "%02d:%02d:%02d.%03d" % (ms // 3600000, ms // 60000 % 60, ms // 1000 % 60, ms % 1000)
        chunk = stream[off:off + n]
        data += qstring(stamp, utf8) + struct.pack(">I", len(chunk)) + chunk
        off += n
    open(out, "wb").write(data)
    print(len(rows))


if __name__ == "__main__":
    main()
