"""lcm_udpm.py -- LCM's UDP multicast (udpm://) in plain Python, so the view runs where no LCM binding is packaged.

Debian (and so a BlueOS extension's base) ships liblcm but no Python binding for it; the view listens, and sends
only sonard's small commands (SONAR_CONTROL, one short datagram each), and
LCM's multicast wire format is small (lcm/lcm_udpm.c and LCM's UDP multicast protocol notes):

  short message:   u32 magic "LC02", u32 sequence, channel NUL, payload           (one datagram)
  fragment:        u32 magic "LC03", u32 sequence, u32 message size, u32 offset,
                   u16 fragment number, u16 fragments; fragment 0: channel NUL, then payload bytes

all big-endian. One message is reassembled per sender at a time (a new sequence number drops an unfinished one,
as LCM does), bounded at MAX_MESSAGE bytes; anything malformed is counted in `bad` and skipped. A sender numbers
its messages one by one, so a gap in a sender's numbers is messages lost on the way (a full socket buffer: a reader
that fell behind): counted in `lost`, for the last MAX_SENDERS senders heard.
The object offers the part of lcm.LCM the view uses: subscribe(regex, handler(channel, data)), fileno(), handle(),
publish(channel, data) (short messages only: a command is a few dozen bytes).
"""
import re
import socket
import struct
from urllib.parse import urlparse, parse_qs

DEFAULT_URL = "udpm://239.255.76.67:7667?ttl=0"  # LCM's own default
MAX_MESSAGE = 1 << 20
MAX_SENDERS = 64  # senders whose last sequence number is kept (a publisher that opens a socket per message is many)
SHORT = 0x4C433032
FRAGMENT = 0x4C433033


class Udpm:
    def __init__(self, url=None):
        u = urlparse(url or DEFAULT_URL)
        if u.scheme != "udpm":
            raise ValueError(f"{url}: only udpm:// is received without LCM's binding")
        group, port = u.hostname or "239.255.76.67", u.port or 7667
        opts = parse_qs(u.query)
        self.bad = self.lost = 0
        self.last_seq = {}  # sender -> the sequence number of its last message begun
        self.subs = []
        self.partial = {}  # sender -> [sequence, channel, buffer, fragments left]
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if hasattr(socket, "SO_REUSEPORT"):
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        rcvbuf = int(opts.get("recv_buf_size", ["0"])[0] or 0)
        if rcvbuf > 0:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        s.bind(("", port))
        s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                     struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton("0.0.0.0")))
        s.setblocking(False)
        self.sock = s
        self.group, self.port, self.seq = group, port, 0
        self.ttl = int(opts.get("ttl", ["0"])[0] or 0)

    def publish(self, channel, data):
        """One short message (LC02) to the group, with the URL's ttl (0: this host only), as LCM sends it."""
        body = struct.pack(">II", SHORT, self.seq) + channel.encode() + b"\0" + bytes(data)
        if len(body) > 65000:
            raise ValueError(f"{channel}: {len(data)} bytes is more than one short message")
        self.seq = (self.seq + 1) & 0xFFFFFFFF
        out = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        try:
            out.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, self.ttl)
            out.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            out.sendto(body, (self.group, self.port))
        finally:
            out.close()

    def subscribe(self, regex, handler):
        self.subs.append((re.compile(regex), handler))

    def fileno(self):
        return self.sock.fileno()

    def _deliver(self, channel, data):
        for rx, h in self.subs:
            if rx.fullmatch(channel):
                h(channel, data)

    def _channel(self, buf, at):
        end = buf.find(b"\0", at)
        if end < 0 or end - at > 255:
            return None, None
        try:
            return buf[at:end].decode("utf-8"), end + 1
        except UnicodeDecodeError:
            return None, None

    def _sequence(self, sender, seq):
        last = self.last_seq.pop(sender, None)
        if last is not None:
            gap = (seq - last - 1) & 0xFFFFFFFF
            if 0 < gap < 1 << 20:  # a sender that restarted numbers anew is not a loss
                self.lost += gap
        self.last_seq[sender] = seq
        if len(self.last_seq) > MAX_SENDERS:
            del self.last_seq[next(iter(self.last_seq))]

    def feed(self, buf, sender):
        """One datagram as LCM sends it; returns nothing, counts what it cannot use."""
        if len(buf) < 8:
            self.bad += 1
            return
        magic, seq = struct.unpack_from(">II", buf, 0)
        if magic == SHORT or (magic == FRAGMENT and len(buf) >= 20 and struct.unpack_from(">H", buf, 16)[0] == 0):
            self._sequence(sender, seq)
        if magic == SHORT:
            channel, at = self._channel(buf, 8)
            if channel is None:
                self.bad += 1
                return
            self._deliver(channel, bytes(buf[at:]))
            return
        if magic != FRAGMENT or len(buf) < 20:
            self.bad += 1
            return
        size, offset, number, count = struct.unpack_from(">IIHH", buf, 8)
        body = buf[20:]
        if size > MAX_MESSAGE or count == 0 or number >= count:
            self.bad += 1
            return
        p = self.partial.get(sender)
        if number == 0:
            channel, at = self._channel(buf, 20)
            if channel is None:
                self.bad += 1
                return
            body = buf[at:]
            p = [seq, channel, bytearray(size), count]
            self.partial[sender] = p
        elif p is None or p[0] != seq:
            self.bad += 1  # a fragment of a message whose start was lost
            return
        if offset + len(body) > size:
            self.bad += 1
            self.partial.pop(sender, None)
            return
        p[2][offset:offset + len(body)] = body
        p[3] -= 1
        if p[3] == 0:
            del self.partial[sender]
            self._deliver(p[1], bytes(p[2]))

    def handle(self):
        """Everything waiting on the socket (the view calls it when the socket is readable)."""
        while True:
            try:
                buf, sender = self.sock.recvfrom(65536)
            except (BlockingIOError, InterruptedError):
                return
            self.feed(buf, sender)
