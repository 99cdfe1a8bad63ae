"""fan.py -- the Ping360's fan as a mono8 image from its beams (numpy): the ROS 2 bridge's image topic and
lcm2mcap's /sonar/fan draw it the same way. A pixel's bearing and radius are worked out once per image size."""


class Fan:
    """The sweep as a top-down mono8 square: the sonar at the centre, ahead up, starboard right, a beam's range at the
    edge. Each pixel's bearing bin (the nearest gradian) and fraction of the radius are worked out once, so a beam
    costs only the pixels of its own wedge; each beam fills the wedge back to the one drawn before it."""

    def __init__(self, size):
        import numpy as np
        self.np, self.size = np, size
        self.img = np.zeros((size, size), np.uint8)
        c = (size - 1) / 2.0
        rows, cols = np.mgrid[0:size, 0:size]
        ahead, stbd = c - rows, cols - c
        frac = np.hypot(ahead, stbd) / (size / 2.0)
        inside = np.flatnonzero(frac < 1.0)
        gbin = (np.floor((np.degrees(np.arctan2(stbd, ahead)) % 360.0) / 0.9 + 0.5).astype(np.int64) % 400).ravel()[inside]
        order = np.argsort(gbin, kind="stable")
        self.pix, self.frac = inside[order], frac.ravel()[inside][order]
        self.start = np.searchsorted(gbin[order], np.arange(401))
        self.last_deg = None

    def draw(self, deg, samples, n):
        """One beam at `deg` (clockwise from ahead) across the gap to the last one drawn (1 to 20 gradians wide)."""
        np = self.np
        if n <= 0:
            return
        s = np.frombuffer(bytes(samples), np.uint8)[:n]
        gap = 0.9 if self.last_deg is None else abs((deg - self.last_deg + 180.0) % 360.0 - 180.0)
        gap = gap if 0.9 <= gap <= 18.0 else 0.9
        self.last_deg = deg
        lo, hi = int(np.floor((deg - gap / 2) / 0.9 + 0.5)), int(np.floor((deg + gap / 2) / 0.9 + 0.5))
        for b in range(lo, max(hi, lo + 1)):
            a, z = self.start[b % 400], self.start[b % 400 + 1]
            self.img.flat[self.pix[a:z]] = s[np.minimum((self.frac[a:z] * n).astype(np.int64), n - 1)]

    def clear(self):
        """Everything drawn forgotten (a new sweep's image from its own beams only)."""
        self.img[:] = 0
        self.last_deg = None
