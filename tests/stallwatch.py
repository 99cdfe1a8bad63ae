#!/usr/bin/env python3
"""stallwatch.py -- the machine's stalls as a process that only sleeps sees them: each wake later than STALL_S after
the last is a stretch when this process (and, on a paused VM or a frozen test, every process) could not run. A live
check takes the stalls within an interval out of it, so that only the program's own lateness can fail it.

As a program: stallwatch.py OUT -- writes one JSON line [start, end] (epoch seconds) per stall until SIGTERM.
As a module: Watch (tick it from a loop that sleeps LOOP_S), load(OUT), overlap(stalls, a, b)."""
import json
import signal
import sys
import time

LOOP_S = 0.005   # the loop's sleep
STALL_S = 0.05   # a wake this much after the last one: a stall


class Watch:
    def __init__(self):
        self.last = time.time()
        self.stalls = []  # (start, end), epoch seconds

    def tick(self):
        """Call once a loop; returns the stall that ended now, or None."""
        now = time.time()
        s = None
        if now - self.last > STALL_S:
            s = (self.last + LOOP_S, now)
            self.stalls.append(s)
        self.last = now
        return s


def overlap(stalls, a, b):
    """Seconds of the stalls within [a, b]."""
    return sum(max(0.0, min(y, b) - max(x, a)) for x, y in stalls)


def load(path):
    with open(path) as f:
        return [tuple(json.loads(line)) for line in f if line.strip()]


def main():
    out = open(sys.argv[1], "w", buffering=1)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    w = Watch()
    while True:
        s = w.tick()
        if s is not None:
            out.write(json.dumps([round(s[0], 4), round(s[1], 4)]) + "\n")
        time.sleep(LOOP_S)


if __name__ == "__main__":
    main()
