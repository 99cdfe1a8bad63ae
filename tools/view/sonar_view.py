#!/usr/bin/env python3
"""sonar_view.py -- a live polar view of sonard in the browser: LCM in, one WebSocket per page out, plain HTML/JS.

  sonar_view.py [--lcm URL] [--listen 127.0.0.1:8360] [--prefix P] [--types build/lcm/python]

It subscribes to SONAR_BEAM, SONAR_BEAM_FILTERED, SONAR_DETECTIONS, SONAR_TRACKS, SONAR_STATUS and SONAR_SURVEY (with
sonard's --channel-prefix) and serves http://ADDR:PORT/ (index.html, view.js) and the WebSocket /ws.
Libraries: `websockets` (HTTP and WebSocket in one small, dependency-free asyncio library) and, for udpm:// (LCM's
default), lcm_udpm.py beside this file; other LCM URLs need LCM's own Python binding. The page is plain JavaScript
on a canvas and uses relative paths only, so it works behind a proxy's prefix (BlueOS shows it at
/extensionv2/sonard/). GET /register_service answers BlueOS's helper (name, icon, version, ...).

Backpressure: a page that cannot keep up gets the newest beam of each angle (older ones are dropped and
counted), never a growing queue: at most PAGE_BEAMS (64) beams wait per page, the oldest dropped first, and at
most IN_FLIGHT (32) are on their way (the page acknowledges what it received at each animation frame). A page that stops reading for 10 s is
closed. Malformed LCM messages are counted and skipped. Without LCM traffic the page says how long the
sonar has been silent; it resumes by itself when sonard comes back.
"""
import argparse
import asyncio
import json
import os
import struct
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
if os.path.isdir(os.path.join(HERE, "vendor")):  # the package's and the BlueOS image's pinned websockets
    sys.path.insert(0, os.path.join(HERE, "vendor"))
PAGE_BEAMS = 64  # beams waiting per page at most (the oldest dropped first): ~2.7 s of a device-paced sonar
IN_FLIGHT = 32   # beams sent and not yet acknowledged by the page


class Client:
    def __init__(self, ws):
        self.ws = ws
        self.filtered = False
        self.beams = {}       # angle -> packed beam, newest only
        self.texts = []       # detections / tracks / status JSON, at most 16 kept
        self.wake = asyncio.Event()
        self.dropped = 0
        self.sent_beams = 0   # beams sent to the page
        self.acked = 0        # beams the page says it has received (it tells at each animation frame)
        self.acked_ev = asyncio.Event()


class Hub:
    def __init__(self, prefix):
        self.prefix = prefix
        self.clients = set()
        self.counts = {"beams": 0, "bad": 0, "dropped": 0}
        self.last_rx = 0.0
        self.last_status = None
        self.last_survey = None  # the survey's structure (SONAR_SURVEY), for a page that joins late
        self.udpm = None  # the plain-Python receiver, when it is the transport (its malformed datagrams count as bad)

    def bad(self):
        return self.counts["bad"] + (self.udpm.bad if self.udpm is not None else 0)

    def beam(self, filtered, data):
        for c in self.clients:
            if c.filtered != filtered:
                continue
            angle = struct.unpack_from("<H", data, 1)[0]
            if angle in c.beams:
                c.dropped += 1  # the page is behind: only the newest beam of an angle is worth drawing
                self.counts["dropped"] += 1
                del c.beams[angle]  # re-inserted below as the newest
            elif len(c.beams) >= PAGE_BEAMS:
                del c.beams[next(iter(c.beams))]  # far behind: the oldest waiting beam goes, so lag stays short
                c.dropped += 1
                self.counts["dropped"] += 1
            c.beams[angle] = data
            c.wake.set()

    def text(self, obj):
        s = json.dumps(obj, separators=(",", ":"))
        for c in self.clients:
            if len(c.texts) >= 16:
                c.texts.pop(0)
                c.dropped += 1
            c.texts.append(s)
            c.wake.set()


def pack_beam(m):
    # kind 1, angle u16, range f32, utime f64 (us), n u16, samples
    n = len(m.samples)
    return struct.pack("<BHfdH", 1, m.angle % 400, m.range_m, float(m.utime), n) + bytes(m.samples)


def status_json(m, hub):
    keys = ["link_state", "link", "fw_major", "fw_minor", "fw_patch", "frames", "checksum_errors", "resyncs",
            "oversize", "bytes_dropped", "timeouts", "retries", "nacks", "reconnects", "off_angle", "foreign", "beams", "sweeps",
            "beams_rejected", "sink_errors", "last_sweep_s", "beam_us_p50", "beam_us_p99", "tracks", "pose_state",
            "passive", "passive_idle", "survey_state", "survey_why", "survey_fixed", "survey_utime", "survey_sweeps",
            "survey_turn_grad", "survey_places"]
    out = {k: getattr(m, k, 0) for k in keys}  # an older sonard's status has no survey: 0, no survey
    out["utime"] = m.utime
    return out


def lcm_setup(url, hub, types_dir):
    sys.path.insert(0, types_dir)
    from sonar import beam_t, detections_t, tracks_t, status_t
    try:
        from sonar import survey_t
    except ImportError:  # types of a sonard before the survey
        survey_t = None
    if not url or url.startswith("udpm://"):
        sys.path.insert(0, HERE)
        from lcm_udpm import Udpm
        lc = Udpm(url)
        hub.udpm = lc
    else:
        import lcm  # file://, tcpq:// ...: LCM's own binding
        lc = lcm.LCM(url)
    p = hub.prefix

    def guard(fn):
        def h(channel, data):
            hub.last_rx = time.time()
            try:
                fn(data)
            except Exception as e:  # a malformed message must not stop the view
                hub.counts["bad"] += 1
                if hub.counts["bad"] <= 5:
                    print(f"sonar_view: {channel}: malformed message skipped ({e})", file=sys.stderr)
        return h

    def on_beam(filtered):
        def f(data):
            m = beam_t.decode(data)
            hub.counts["beams"] += 1
            hub.beam(filtered, pack_beam(m))
        return f

    def on_det(data):
        m = detections_t.decode(data)
        hub.text({"kind": "detections", "sweep": m.sweep, "utime": m.utime, "detections": [
            {"x": d.x_m, "y": d.y_m, "structure": d.kind == 1, "since_start": d.kind == 2,
             "hull": [[x, y] for x, y in zip(d.hull_x, d.hull_y)]}
            for d in m.detections]})

    def on_trk(data):
        m = tracks_t.decode(data)
        kinds, modes = ("new", "moving", "resting", "structure", "static since start"), ("moving", "turning", "resting")
        hub.text({"kind": "tracks", "sweep": m.sweep, "tracks": [
            {"id": k.id, "state": k.state, "x": k.x_m, "y": k.y_m, "what": kinds[k.kind] if 0 <= k.kind < 5 else "?",
             "mode": modes[k.mode] if 0 <= k.mode < 3 else "?", "still_s": k.still_s} for k in m.tracks],
            # the last sweep's IDs this look revised: published as id, now as now (0: withdrawn)
            "revisions": [{"id": a, "now": b} for a, b in zip(m.revised_from, m.revised_to)]})

    def on_status(data):
        m = status_t.decode(data)
        hub.last_status = status_json(m, hub)
        hub.text({"kind": "status", "status": hub.last_status})

    lc.subscribe(p + "SONAR_BEAM$", guard(on_beam(False)))
    lc.subscribe(p + "SONAR_BEAM_FILTERED$", guard(on_beam(True)))
    lc.subscribe(p + "SONAR_DETECTIONS$", guard(on_det))
    lc.subscribe(p + "SONAR_TRACKS$", guard(on_trk))
    def on_survey(data):
        m = survey_t.decode(data)
        hub.last_survey = {"kind": "survey", "state": m.state, "fixed": m.fixed, "recorded_utime": m.recorded_utime,
                           "places": [{"x": d.x_m, "y": d.y_m, "line": d.kind == 1,
                                       "hull": [[x, y] for x, y in zip(d.hull_x, d.hull_y)]} for d in m.places]}
        hub.text(hub.last_survey)

    lc.subscribe(p + "SONAR_STATUS$", guard(on_status))
    if survey_t is not None:
        lc.subscribe(p + "SONAR_SURVEY$", guard(on_survey))
    return lc


async def sender(c):
    while True:
        await c.wake.wait()
        c.wake.clear()
        while c.texts or c.beams:
            if c.texts:
                msg = c.texts.pop(0)
            else:
                # Flow control: at most IN_FLIGHT beams between here and the page's canvas. Kernel socket
                # buffers hold seconds of beams; waiting here keeps the backlog in c.beams, where it is dropped.
                while c.sent_beams - c.acked >= IN_FLIGHT and not c.texts:
                    c.acked_ev.clear()
                    try:
                        await asyncio.wait_for(c.acked_ev.wait(), timeout=10)
                    except asyncio.TimeoutError:
                        c.acked = c.sent_beams  # an old page that does not acknowledge: go on unthrottled
                if c.texts or not c.beams:
                    continue
                angle = next(iter(c.beams))
                msg = c.beams.pop(angle)
                c.sent_beams += 1
            # a page that stops reading is closed rather than buffered for
            await asyncio.wait_for(c.ws.send(msg), timeout=10)


async def handler(ws, hub):
    c = Client(ws)
    hub.clients.add(c)
    if hub.last_status is not None:
        c.texts.append(json.dumps({"kind": "status", "status": hub.last_status}))
        c.wake.set()
    if hub.last_survey is not None:
        c.texts.append(json.dumps(hub.last_survey))
        c.wake.set()
    task = asyncio.create_task(sender(c))
    try:
        async for msg in ws:
            try:
                req = json.loads(msg)
            except ValueError:
                continue
            if "filtered" in req:
                c.filtered = bool(req["filtered"])
                c.beams.clear()
            if isinstance(req.get("received"), int):
                c.acked = req["received"]
                c.acked_ev.set()
    except Exception:
        pass
    finally:
        hub.clients.discard(c)
        task.cancel()


async def ticker(hub):
    """Once a second: the view's own health, so a page knows when the sonar went quiet."""
    while True:
        await asyncio.sleep(1.0)
        silent = time.time() - hub.last_rx if hub.last_rx else None
        hub.text({"kind": "view", "silent_s": silent, "beams": hub.counts["beams"], "bad": hub.bad(),
                  "dropped": hub.counts["dropped"], "pages": len(hub.clients)})


def version():
    """sonard's version: the package writes it beside the view; in the tree, src/host/version.h has it."""
    for path, pick in ((os.path.join(HERE, "VERSION"), lambda t: t.strip()),
                       (os.path.join(HERE, "..", "..", "src", "host", "version.h"),
                        lambda t: t.split('SONARD_VERSION "', 1)[1].split('"', 1)[0])):
        try:
            with open(path) as f:
                return pick(f.read())
        except (OSError, IndexError):
            continue
    return "0.0.0"


def register_service():
    """BlueOS's helper asks every port it finds listening on 0.0.0.0 for this (services/helper/main.py)."""
    return {"name": "sonard", "description": "Ping360 sonar to live object detections and tracks, obstacles for the "
            "autopilot: the live view", "icon": "mdi-radar", "company": "sonard", "version": version(),
            "webpage": os.environ.get("SONARD_WEBPAGE", ""), "api": "", "new_page": False,
            "works_in_relative_paths": True}


async def main_async(a):
    from websockets.asyncio.server import serve
    from websockets.datastructures import Headers
    from websockets.http11 import Response

    hub = Hub(a.prefix)
    lc = lcm_setup(a.lcm, hub, a.types)
    loop = asyncio.get_running_loop()
    loop.add_reader(lc.fileno(), lc.handle)
    files = {"/": ("index.html", "text/html; charset=utf-8"), "/index.html": ("index.html", "text/html; charset=utf-8"),
             "/view.js": ("view.js", "application/javascript; charset=utf-8")}

    def http(connection, request):
        path = request.path.split("?")[0]
        if path == "/ws":
            return None  # the WebSocket handshake goes on
        if path in files:
            name, ctype = files[path]
            body = open(os.path.join(HERE, name), "rb").read()
        elif path == "/register_service":
            body, ctype = json.dumps(register_service()).encode(), "application/json"
        elif path == "/health":
            body, ctype = json.dumps({"counts": dict(hub.counts, bad=hub.bad()), "pages": len(hub.clients),
                                      "silent_s": time.time() - hub.last_rx if hub.last_rx else None}).encode(), "application/json"
        else:
            return connection.respond(404, "not found\n")
        return Response(200, "OK", Headers([("Content-Type", ctype), ("Content-Length", str(len(body))),
                                            ("Cache-Control", "no-store")]), body)

    host, port = a.listen.rsplit(":", 1)
    async with serve(lambda ws: handler(ws, hub), host, int(port), process_request=http, max_size=1 << 16,
                     ping_interval=5, ping_timeout=10):
        print(f"sonar_view: http://{host}:{port}/ (LCM {a.lcm or 'default'}, prefix '{a.prefix}')", file=sys.stderr, flush=True)
        asyncio.create_task(ticker(hub))
        await asyncio.Future()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lcm", default=os.environ.get("LCM_DEFAULT_URL"), help="LCM URL (default: LCM's own)")
    ap.add_argument("--listen", default="127.0.0.1:8360", help="ADDR:PORT to serve the page on")
    ap.add_argument("--prefix", default="", help="sonard's --channel-prefix")
    ap.add_argument("--types", default=os.environ.get("SONARD_LCM_PY", "build/lcm/python"),
                    help="directory holding the generated 'sonar' package")
    a = ap.parse_args()
    try:
        asyncio.run(main_async(a))
    except KeyboardInterrupt:
        pass
    except OSError as e:
        raise SystemExit(f"sonar_view: --listen {a.listen}: {e.strerror}")


if __name__ == "__main__":
    main()
