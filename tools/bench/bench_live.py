#!/usr/bin/env python3
"""bench_live.py -- the live daemon against sonar-feed pacing real device timing: sweep time, recovery
from one lost reply, CPU and peak RSS. Everything on 127.0.0.1; every figure from this one run.

Usage: bench_live.py BUILD_DIR [--range 2]
"""
import argparse
import csv
import os
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rss  # noqa: E402


def feed(b, port, log, *extra):
    p = subprocess.Popen([f"{b}/sonar-feed", "--listen", f"tcp:127.0.0.1:{port}", "--scene", "pool", "--pace", "device",
                          "--exit-after-motor-off", "--max-seconds", "300", "--log", log, *extra],
                         stderr=subprocess.DEVNULL)
    time.sleep(0.3)
    return p


def beam_times(path):
    t = []
    with open(path) as f:
        for row in csv.reader(f):
            t.append((int(row[0]) + int(row[1]) * 1e-9, int(row[2])))
    return t


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("build")
    ap.add_argument("--range", type=float, default=2.0)
    a = ap.parse_args()
    c, r, step = 1500.0, a.range, 1
    model_beam = 0.0194 + 0.006 * step + 2 * r / c
    port = 30000 + os.getpid() % 20000
    with tempfile.TemporaryDirectory() as d:
        # 1. two full sweeps at device pace: the second is timed beam to beam (400 beams)
        fp = feed(a.build, port, f"{d}/f1.log")
        # sonard's own figures from /proc (RUSAGE_CHILDREN's maxrss would be Python's: see tools/bench/rss.py),
        # with LCM publishing to a file log as a vehicle would
        t0 = time.time()
        sp = subprocess.Popen([f"{a.build}/sonard", "--sonar", f"tcp:127.0.0.1:{port}", "--range", str(r), "--sweeps", "2",
                               "--lcm", f"file://{d}/run.lcm?mode=w", "--quiet", "--csv-out", f"{d}/run.csv"])
        hwm, parts, cpu = 0, {}, 0.0
        while sp.poll() is None:
            s = rss.status(sp.pid)
            if s is not None:
                hwm = max(hwm, s["VmHWM"])
                try:
                    parts, cpu = rss.breakdown(sp.pid), rss.cpu_seconds(sp.pid)
                except (FileNotFoundError, ProcessLookupError):
                    pass
            time.sleep(0.5)
        wall = time.time() - t0
        fp.wait(timeout=10)
        rss_mb = hwm / 1024.0
        t = beam_times(f"{d}/run.csv")
        # sweep 1 = rows 400..799 (full turns from angle 0): first beam of sweep 1 to first beam of sweep 2
        sweep_s = t[800][0] - t[400][0]
        model_s = 400 * model_beam
        # 2. one lost reply at beam 600: how long until the next beam, against the expected beam time
        fp = feed(a.build, port + 1, f"{d}/f2.log", "--drop-at", "600")
        subprocess.run([f"{a.build}/sonard", "--sonar", f"tcp:127.0.0.1:{port + 1}", "--range", str(r), "--sweeps", "2",
                        "--no-lcm", "--quiet", "--csv-out", f"{d}/drop.csv"], timeout=120)
        fp.wait(timeout=10)
        t2 = beam_times(f"{d}/drop.csv")
        gaps = [(t2[i + 1][0] - t2[i][0], i) for i in range(len(t2) - 1)]
        worst_gap, at = max(gaps)
        normal = sorted(g for g, _ in gaps)[len(gaps) // 2]
        # the reply that never came was due one beam after the last good one; the retry's beam arrived worst_gap later
        resume_after_loss = worst_gap - normal
    print(f"live bench (one run; range {r} m, 1-gradian steps, 400-beam sweeps, sonar-feed at device pace, TCP loopback)")
    print(f"  sweep time             {sweep_s:8.3f} s   model {model_s:.3f} s   ratio {sweep_s / model_s:.3f}   (target <= 1.05)")
    print(f"  median beam interval   {normal * 1e3:8.1f} ms  model {model_beam * 1e3:.1f} ms")
    print(f"  lost reply: next beam  {worst_gap * 1e3:8.1f} ms after the last; resumed {resume_after_loss * 1e3:.1f} ms after the "
          f"lost one was due = {resume_after_loss / model_beam:.2f} beam times   (target <= 2; brping waits 4 s, ROS 8 s)")
    print(f"  CPU                    {cpu:8.3f} s over {wall:.1f} s = {100 * cpu / wall:.2f} % of one core   (target <= 1 %)")
    print(f"  peak RSS (VmHWM)       {rss_mb:8.1f} MB   (target <= 16 MB), of which:")
    for k, v in sorted(parts.items(), key=lambda kv: -kv[1]):
        print(f"      {v / 1024.0:6.2f} MB  {k}")
    ok = sweep_s / model_s <= 1.05 and resume_after_loss <= 2 * model_beam and 100 * cpu / wall <= 1.0 and rss_mb <= 16
    print("  targets:", "met" if ok else "MISSED")
    return 0


if __name__ == "__main__":
    sys.exit(main())
