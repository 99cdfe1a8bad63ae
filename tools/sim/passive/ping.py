"""ping.py -- the Ping Protocol as the passive-mode simulators need it: framing, a stream parser, the Ping360's
transducer / auto_transmit requests and device_data / auto_device_data replies (reference/ping.md)."""
import struct

DEVICE_INFORMATION, GENERAL_REQUEST = 4, 6
DEVICE_DATA, AUTO_DEVICE_DATA = 2300, 2301
RESET, TRANSDUCER, AUTO_TRANSMIT, MOTOR_OFF = 2600, 2601, 2602, 2903
HEAD_COMMANDS = {RESET, TRANSDUCER, AUTO_TRANSMIT, MOTOR_OFF}  # every message that moves or sets the head


def frame(msg_id, payload=b"", src=0, dst=0):
    head = b"BR" + struct.pack("<HHBB", len(payload), msg_id, src, dst) + payload
    return head + struct.pack("<H", sum(head) & 0xFFFF)


class Parser:
    """Bytes in, whole frames out as (id, payload); bad checksums and junk are skipped and counted."""

    def __init__(self):
        self.buf = bytearray()
        self.bad = 0

    def feed(self, data):
        self.buf += data
        out = []
        while True:
            i = self.buf.find(b"BR")
            if i < 0:
                self.buf = self.buf[-1:] if self.buf[-1:] == b"B" else bytearray()
                return out
            del self.buf[:i]
            if len(self.buf) < 10:
                return out
            n, mid = struct.unpack_from("<HH", self.buf, 2)
            if n > 2048:
                self.bad += 1
                del self.buf[:2]
                continue
            if len(self.buf) < 10 + n:
                return out
            body = bytes(self.buf[:8 + n])
            if struct.unpack_from("<H", self.buf, 8 + n)[0] != sum(body) & 0xFFFF:
                self.bad += 1
                del self.buf[:2]
                continue
            out.append((mid, body[8:]))
            del self.buf[:10 + n]


def transducer(gain, angle, tx_us, sample_period, freq, samples):
    return frame(TRANSDUCER, struct.pack("<BBHHHHHBB", 1, gain, angle, tx_us, sample_period, freq, samples, 1, 0))


def auto_transmit(gain, tx_us, sample_period, freq, samples, start, stop, step):
    return frame(AUTO_TRANSMIT, struct.pack("<BBHHHHHHBB", 1, gain, tx_us, sample_period, freq, samples, start, stop, step, 0))


def beam(msg_id, p):
    """A device_data or auto_device_data payload as a dict (angle, gain, sample_period, ..., data)."""
    if msg_id == DEVICE_DATA and len(p) >= 14:
        _, gain, angle, tx, sp, freq, ns, dl = struct.unpack_from("<BBHHHHHH", p, 0)
        return dict(gain=gain, angle=angle, tx=tx, sp=sp, freq=freq, n=dl, data=p[14:14 + dl], auto=0)
    if msg_id == AUTO_DEVICE_DATA and len(p) >= 20:
        _, gain, angle, tx, sp, freq, _s, _e, _st, _d, ns, dl = struct.unpack_from("<BBHHHHHHBBHH", p, 0)
        return dict(gain=gain, angle=angle, tx=tx, sp=sp, freq=freq, n=dl, data=p[20:20 + dl], auto=1)
    return None


def sample_period(range_m, samples, c=1500.0):
    """Ticks of 25 ns so that `samples` samples cover range_m (Ping Viewer's rule)."""
    return max(80, min(40000, round(2.0 * range_m / (samples * c) / 25e-9)))
