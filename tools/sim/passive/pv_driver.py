#!/usr/bin/env python3
"""pv_driver.py -- a program driving the head as Ping Viewer does, through a bridge, for the passive-mode tests:
stepped (one transducer request per angle, the next sent when the reply comes, the last re-sent after 0.5 s of
silence) or auto_transmit (one request; the head streams auto_device_data). Its sector, step, range and gain are
its own; --schedule changes them mid-run ("W:key=value,...", W the sweep it happens at, e.g. 2:gain=1 or
4:range=20: at the first beam of that sweep, counted from 0), and "W:pause=S" stops driving for S seconds (a stepped driver sends nothing then; an auto one sends motor_off, then
auto_transmit again). Every beam it receives goes to --out as the study's CSV with its settings (sample_period,
gain, ...), so that `sonard --replay` of it is the beams this driver saw.
Usage: pv_driver.py --bridge 127.0.0.1:9092 --mode step|auto --range 12 --step 1 [--sector 0:399] [--gain 0]
       [--samples 1200] [--sweeps N | --seconds S] [--schedule ...] --out FILE.csv"""
import argparse
import os
import socket
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ping  # noqa: E402


def main():
    a = argparse.ArgumentParser()
    a.add_argument("--bridge", required=True)
    a.add_argument("--mode", choices=["step", "auto"], default="step")
    a.add_argument("--range", type=float, default=12.0)
    a.add_argument("--step", type=int, default=1)
    a.add_argument("--sector", default="0:399")
    a.add_argument("--gain", type=int, default=0)
    a.add_argument("--samples", type=int, default=1200)
    a.add_argument("--frequency", type=int, default=750)
    a.add_argument("--sweeps", type=int, default=0)
    a.add_argument("--seconds", type=float, default=60)
    a.add_argument("--schedule", default="")
    a.add_argument("--out", required=True)
    o = a.parse_args()
    h, p = o.bridge.rsplit(":", 1)
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.connect((h, int(p)))
    s.settimeout(0.05)
    start, stop = (int(x) for x in o.sector.split(":"))
    full = start == 0 and stop == 399
    st = {"range": o.range, "gain": o.gain, "step": o.step, "samples": o.samples}
    sched = []
    for item in filter(None, o.schedule.split(",")):
        t, kv = item.split(":", 1)
        k, v = kv.split("=")
        sched.append([float(t), k, float(v)])
    sched.sort()
    parser = ping.Parser()
    out = open(o.out, "w")
    t0 = time.time()
    angle, direction, sweeps, beams = start, 1, 0, 0
    paused_until = 0.0

    def request():
        sp = ping.sample_period(st["range"], st["samples"])
        if o.mode == "auto":
            s.send(ping.auto_transmit(st["gain"], 0, sp, o.frequency, st["samples"], 0 if full else start,
                                      399 if full else stop, st["step"]))
        else:
            s.send(ping.transducer(st["gain"], angle, 0, sp, o.frequency, st["samples"]))

    request()
    last_sent = time.time()
    end = t0 + o.seconds
    while time.time() < end and (o.sweeps == 0 or sweeps < o.sweeps):
        now = time.time()
        while sched and sweeps >= sched[0][0] and not paused_until:
            _, k, v = sched.pop(0)
            if k == "pause":
                paused_until = now + v
                print(f"pv_driver: paused at {now:.3f} for {v:g} s", file=sys.stderr, flush=True)
                if o.mode == "auto":
                    s.send(ping.frame(ping.MOTOR_OFF))
            else:
                st[k] = int(v) if k != "range" else v
                if o.mode == "auto":
                    request()
        if paused_until and now >= paused_until:
            paused_until = 0.0
            request()
            last_sent = now
        try:
            data = s.recv(65536)
        except socket.timeout:
            if not paused_until and o.mode == "step" and time.time() - last_sent > 0.5:
                request()  # a lost request or reply: ask again, as Ping Viewer does
                last_sent = time.time()
            continue
        for mid, payload in parser.feed(data):
            b = ping.beam(mid, payload)
            if b is None or b["n"] == 0:
                continue
            t = time.time()
            out.write("%d,%09d,%d,\"%s\",sample_period=%d,gain=%d,transmit_duration=%d,transmit_frequency=%d\n" % (
                int(t), int((t % 1) * 1e9), b["angle"], " ".join(str(x) for x in b["data"]), b["sp"], b["gain"], b["tx"],
                b["freq"]))
            beams += 1
            if o.mode == "auto":
                if b["angle"] < angle and full:
                    sweeps += 1
                angle = b["angle"]
                continue
            if b["angle"] != angle or paused_until:
                continue
            # the next angle: full turns, or back and forth in the sector
            if full:
                nxt = (angle + st["step"]) % 400
                if nxt < angle:
                    sweeps += 1
            else:
                nxt = angle + direction * st["step"]
                if nxt > stop or nxt < start:
                    direction = -direction
                    sweeps += 1
                    nxt = angle + direction * st["step"]
            angle = nxt
            if o.sweeps and sweeps >= o.sweeps:
                break  # no request after the last beam: every reply drawn is one this driver records
            request()
            last_sent = time.time()
    if o.mode == "auto":
        s.send(ping.frame(ping.MOTOR_OFF))
    out.close()
    print(f"pv_driver: {beams} beams, {sweeps} sweeps, {time.time() - t0:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
