#!/usr/bin/env python3
"""sonar_view.py -- a live polar view of sonard in the browser: LCM in, one WebSocket per page out, plain HTML/JS.

  sonar_view.py [--lcm URL] [--listen 127.0.0.1:8360] [--prefix P] [--types build/lcm/python]

It subscribes to SONAR_BEAM, SONAR_BEAM_FILTERED, SONAR_DETECTIONS, SONAR_TRACKS, SONAR_STATUS, SONAR_SURVEY and
SONAR_CLUTTER (with sonard's --channel-prefix) and serves http://ADDR:PORT/ (index.html, view.js) and the WebSocket /ws.
Libraries: `websockets` (HTTP and WebSocket in one small, dependency-free asyncio library) and, for udpm:// (LCM's
default), lcm_udpm.py beside this file; other LCM URLs need LCM's own Python binding. The page is plain JavaScript
on a canvas and uses relative paths only, so it works behind a proxy's prefix (BlueOS shows it at
/extensionv2/sonard/). GET /register_service answers BlueOS's helper (name, icon, version, ...).

Cockpit (BlueOS's control station) finds two widgets (widget_fan.html, widget_status.html: tiles reading this
server's one stream) and two actions through /register_service's extras.cockpit -> /cockpit_extras.json.
The actions are HTTP requests to POST control/survey?sweeps=N and POST control/survey/cancel, turned into one
SONAR_CONTROL command each and answered from SONAR_STATUS (sonard takes them only with --control: else 403).
The websockets library parses GET alone, so its connection class is given one that takes control/ requests out of
the stream before its parser sees them; the pages and the WebSocket are served by the library as before.

Backpressure: a page that cannot keep up gets the newest beam of each angle (older ones are dropped and
counted), never a growing queue: at most PAGE_BEAMS (64) beams wait per page, the oldest dropped first, and at
most IN_FLIGHT (32) are on their way (the page acknowledges what it received at each animation frame). A page that stops reading for 10 s is
closed. Malformed LCM messages are counted and skipped. Without LCM traffic the page says how long the
sonar has been silent; it resumes by itself when sonard comes back.
"""
import argparse
import asyncio
import json
import math
import os
import struct
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
if os.path.isdir(os.path.join(HERE, "vendor")):  # the package's and the BlueOS image's pinned websockets
    sys.path.insert(0, os.path.join(HERE, "vendor"))
CONTROL_BODY_MAX = 1024   # a control request's body at most (Cockpit sends none); more is refused, 413
CONTROL_ANSWER_S = 5.0    # how long a control request waits for sonard's answer on SONAR_STATUS
HEAD_MAX = 16384          # a control request's head at most
PAGE_BEAMS = 64  # beams waiting per page at most (the oldest dropped first): ~2.7 s of a device-paced sonar
IN_FLIGHT = 32   # beams sent and not yet acknowledged by the page


class Client:
    def __init__(self, ws):
        self.ws = ws
        self.filtered = False
        self.want_beams = True  # the status tile asks for none
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
        self.last_clutter = None  # the clutter map (SONAR_CLUTTER), likewise
        self.udpm = None  # the plain-Python receiver, when it is the transport (its malformed datagrams count as bad)
        self.lc = None    # the LCM object, for SONAR_CONTROL
        self.control_t = None
        self.seq = int(time.time()) & 0x3FFFFFFF  # commands' seq: not reused by a restarted view for a long while
        self.answers = {}  # seq -> future, resolved by the status that answers it
        self.still_alarm_s = 60.0

    def bad(self):
        return self.counts["bad"] + (self.udpm.bad if self.udpm is not None else 0)

    def beam(self, filtered, data):
        for c in self.clients:
            if c.filtered != filtered or not c.want_beams:
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
            "survey_turn_grad", "survey_places", "control", "control_seq", "control_result", "control_said",
            "survey_rec", "survey_rec_sweeps", "survey_rec_of", "survey_rec_said", "blank_beams", "interference_beams"]
    out = {k: getattr(m, k, 0) for k in keys}  # an older sonard's status has no survey or control: 0, none
    out["utime"] = m.utime
    return out


def lcm_setup(url, hub, types_dir):
    sys.path.insert(0, types_dir)
    from sonar import beam_t, detections_t, tracks_t, status_t
    try:
        from sonar import control_t
    except ImportError:  # types of a sonard before --control
        control_t = None
    hub.control_t = control_t
    try:
        from sonar import survey_t
    except ImportError:  # types of a sonard before the survey
        survey_t = None
    try:
        from sonar import clutter_t
    except ImportError:  # types of a sonard before the clutter map
        clutter_t = None
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
            {"x": d.x_m, "y": d.y_m, "structure": d.kind in (1, 3), "echo": d.kind == 3, "since_start": d.kind == 2,
             "hull": [[x, y] for x, y in zip(d.hull_x, d.hull_y)]}
            for d in m.detections]})

    def on_trk(data):
        m = tracks_t.decode(data)
        kinds, modes = ("new", "moving", "resting", "still", "static since start"), ("moving", "turning", "resting")
        acts = ("unknown", "moving", "standing", "struggling")
        hub.text({"kind": "tracks", "sweep": m.sweep, "tracks": [
            {"id": k.id, "state": k.state, "x": k.x_m, "y": k.y_m, "what": kinds[k.kind] if 0 <= k.kind < 5 else "?",
             "mode": modes[k.mode] if 0 <= k.mode < 3 else "?", "still_s": k.still_s,
             "activity": acts[k.activity] if 0 <= k.activity < 4 else "?",
             "echo_corr": None if math.isnan(k.echo_corr) else round(k.echo_corr, 2),
             "alarms": [a for b, a in ((1, "struggle"), (2, "still")) if k.alarms & b]} for k in m.tracks],
            # the last sweep's IDs this look revised: published as id, now as now (0: withdrawn)
            "revisions": [{"id": a, "now": b} for a, b in zip(m.revised_from, m.revised_to)]})

    def on_status(data):
        m = status_t.decode(data)
        hub.last_status = status_json(m, hub)
        f = hub.answers.pop(hub.last_status["control_seq"], None)
        if f is not None and not f.done():
            f.set_result(hub.last_status)
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

    def on_clutter(data):
        m = clutter_t.decode(data)
        if m.cells != m.bands * m.sectors or m.bands <= 0 or m.sectors <= 0:
            raise ValueError(f"{m.cells} cells for {m.bands} bands x {m.sectors} sectors")
        hub.last_clutter = {"kind": "clutter", "range_m": m.range_m, "bands": m.bands, "sectors": m.sectors,
                            "looks": m.looks, "site": m.site, "per_look": m.per_look,
                            "density": [round(d, 5) for d in m.density]}
        hub.text(hub.last_clutter)

    lc.subscribe(p + "SONAR_STATUS$", guard(on_status))
    if survey_t is not None:
        lc.subscribe(p + "SONAR_SURVEY$", guard(on_survey))
    if clutter_t is not None:
        lc.subscribe(p + "SONAR_CLUTTER$", guard(on_clutter))
    hub.lc = lc
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
    for last in (hub.last_survey, hub.last_clutter):
        if last is not None:
            c.texts.append(json.dumps(last))
            c.wake.set()
    task = asyncio.create_task(sender(c))
    try:
        async for msg in ws:
            try:
                req = json.loads(msg)
            except ValueError:
                continue
            if "beams" in req:  # the status tile: text only
                c.want_beams = bool(req["beams"])
                c.beams.clear()
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
                  "dropped": hub.counts["dropped"], "pages": len(hub.clients), "still_alarm_s": hub.still_alarm_s})


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
            "works_in_relative_paths": True, "extras": {"cockpit": "/cockpit_extras.json"}}


def sanitized(name):
    """BlueOS's helper's sanitized_name: the name, lower case, letters and digits only (its /extensionv2/ path)."""
    return "".join(ch for ch in name.lower() if ch.isascii() and ch.isalnum())


def cockpit_extras():
    """What Cockpit reads (src/libs/blueos.ts): widgets' URLs are relative to the service's base (Cockpit prefixes
    /extensionv2/<sanitized_name>); actions' are not prefixed, so they name the vehicle through Cockpit's data-lake
    variable vehicle-address, and the extension's path."""
    base = "http://{{ vehicle-address }}/extensionv2/" + sanitized(register_service()["name"])
    v = version()

    def action(ident, name, path, params):
        return {"id": ident, "name": name, "type": "http-request",
                "config": {"name": name, "url": base + path, "method": "POST", "headers": {}, "urlParams": params,
                           "body": ""}}
    return {"target_system": "cockpit", "target_cockpit_api_version": "1.0.0",
            "widgets": [{"name": "sonard: sonar", "iframe_url": "/widget_fan.html", "iframe_icon": "/icon.svg",
                         "config_iframe_url": None, "version": v},
                        {"name": "sonard: status and alarms", "iframe_url": "/widget_status.html",
                         "iframe_icon": "/icon.svg", "config_iframe_url": None, "version": v}],
            "actions": [action("sonard-record-survey", "sonard: record the site survey (20 sweeps)", "/control/survey",
                               {"sweeps": "20"}),
                        action("sonard-cancel-survey", "sonard: cancel the site survey", "/control/survey/cancel", {})]}


CONTROL_OFF = ("control is off: sonard takes commands only when it runs with --control (control = on in its "
               "configuration; the BlueOS extension's blueos.conf has it on)")


async def control(hub, method, target, body_len):
    """One control request: (status, JSON object). The commands: POST control/survey?sweeps=N (8..255), POST
    control/survey/cancel. Nothing is sent to sonard unless the request is well formed and sonard takes commands."""
    from urllib.parse import urlsplit, parse_qs
    u = urlsplit(target)
    path = u.path.rstrip("/")
    known = {"/control/survey": 1, "/control/survey/cancel": 2}
    if path not in known:
        return 404, {"error": f"unknown command {path}: the commands are POST control/survey?sweeps=N and POST "
                              "control/survey/cancel"}
    if method != "POST":
        return 405, {"error": f"{method} {path}: a command is a POST"}
    if body_len > CONTROL_BODY_MAX:
        return 413, {"error": f"a body of {body_len} bytes: a command takes none (at most {CONTROL_BODY_MAX})"}
    command, sweeps = known[path], 0
    if command == 1:
        q = parse_qs(u.query)
        try:
            sweeps = int(q.get("sweeps", ["20"])[-1])
        except ValueError:
            return 400, {"error": f"sweeps={q.get('sweeps')[-1]!r}: a whole number 8..255"}
        if not 8 <= sweeps <= 255:
            return 400, {"error": f"sweeps={sweeps}: a survey is 8..255 sweeps"}
    st = hub.last_status
    if st is None or hub.control_t is None or hub.lc is None:
        return 503, {"error": "no status from sonard yet: is it running on this LCM bus?"}
    if not st.get("control"):
        return 403, {"error": CONTROL_OFF}
    hub.seq = hub.seq % 0x7FFFFFFF + 1
    seq = hub.seq
    m = hub.control_t()
    m.utime, m.seq, m.command, m.sweeps = int(time.time() * 1e6), seq, command, sweeps
    fut = asyncio.get_running_loop().create_future()
    hub.answers[seq] = fut
    try:
        hub.lc.publish(hub.prefix + "SONAR_CONTROL", m.encode())
        st = await asyncio.wait_for(fut, CONTROL_ANSWER_S)
    except asyncio.TimeoutError:
        return 504, {"error": f"sonard did not answer command {seq} within {CONTROL_ANSWER_S:.0f} s"}
    finally:
        hub.answers.pop(seq, None)
    out = {k: st[k] for k in ("control_seq", "control_result", "control_said", "survey_rec", "survey_rec_sweeps",
                              "survey_rec_of", "survey_rec_said")}
    out["taken"] = st["control_result"] == 1
    return (200 if out["taken"] else 409), out


REASONS = {200: "OK", 400: "Bad Request", 403: "Forbidden", 404: "Not Found", 405: "Method Not Allowed",
           409: "Conflict", 413: "Payload Too Large", 431: "Request Header Fields Too Large", 503: "Service Unavailable",
           504: "Gateway Timeout"}


def response(code, obj):
    """An HTTP/1.1 response with a JSON body, closing the connection."""
    body = (json.dumps(obj) + "\n").encode()
    extra = "Allow: POST\r\n" if code == 405 else ""
    return (f"HTTP/1.1 {code} {REASONS.get(code, 'Error')}\r\nContent-Type: application/json\r\n"
            f"Content-Length: {len(body)}\r\n{extra}Cache-Control: no-store\r\nConnection: close\r\n\r\n").encode() + body


def connection_class(hub):
    """websockets' server connection, which takes control/ requests (any method: the library parses GET alone) out of
    the stream before its HTTP parser sees them; everything else (the pages, the WebSocket) goes to it untouched."""
    from websockets.asyncio.server import ServerConnection

    class Conn(ServerConnection):
        def connection_made(self, transport):
            self.head, self.stage = b"", "?"  # the request so far: "?" undecided, "ws" websockets', "control" one of ours, "answered"
            super().connection_made(transport)

        def data_received(self, data):
            if self.stage == "ws":
                return super().data_received(data)
            if self.stage == "answered":
                return  # a control request's body: its length was checked, it is not read
            self.head += data
            if self.stage == "?" and b"\r\n" in self.head:
                target = (self.head.split(b"\r\n", 1)[0].split(b" ") + [b"", b""])[1].decode("latin-1")
                control_path = target.split("?")[0] == "/control" or target.startswith("/control/")
                self.stage = "control" if control_path else "ws"
            elif self.stage == "?" and len(self.head) > HEAD_MAX:
                self.stage = "ws"  # a line that long is websockets' to refuse
            if self.stage == "ws":
                data, self.head = self.head, b""
                return super().data_received(data)
            if self.stage == "control" and (b"\r\n\r\n" in self.head or len(self.head) > HEAD_MAX):
                self.stage = "answered"
                asyncio.get_running_loop().create_task(self.answer(self.head))

        async def answer(self, head):
            if b"\r\n\r\n" not in head:
                code, obj = 431, {"error": f"a request head over {HEAD_MAX} bytes"}
            else:
                lines = head.split(b"\r\n\r\n", 1)[0].split(b"\r\n")
                method, target = (lines[0].decode("latin-1").split(" ") + ["", ""])[:2]
                n = 0
                for h in lines[1:]:
                    k, _, v = h.partition(b":")
                    if k.strip().lower() == b"content-length":
                        n = int(v.strip()) if v.strip().isdigit() else CONTROL_BODY_MAX + 1
                    elif k.strip().lower() == b"transfer-encoding":
                        n = CONTROL_BODY_MAX + 1  # a chunked body: refused as too large rather than read
                code, obj = await control(hub, method, target, n)
            if not self.transport.is_closing():
                self.transport.write(response(code, obj))
                self.transport.close()
    return Conn


async def main_async(a):
    from websockets.asyncio.server import serve
    from websockets.datastructures import Headers
    from websockets.http11 import Response

    hub = Hub(a.prefix)
    hub.still_alarm_s = a.still_alarm
    lc = lcm_setup(a.lcm, hub, a.types)
    loop = asyncio.get_running_loop()
    loop.add_reader(lc.fileno(), lc.handle)
    html, js = "text/html; charset=utf-8", "application/javascript; charset=utf-8"
    files = {"/": ("index.html", html), "/index.html": ("index.html", html), "/view.js": ("view.js", js),
             "/widget_fan.html": ("widget_fan.html", html), "/widget_status.html": ("widget_status.html", html),
             "/widget_status.js": ("widget_status.js", js), "/icon.svg": ("icon.svg", "image/svg+xml")}

    def http(connection, request):
        path = request.path.split("?")[0]
        if path == "/ws":
            return None  # the WebSocket handshake goes on
        if path in files:
            name, ctype = files[path]
            body = open(os.path.join(HERE, name), "rb").read()
        elif path == "/register_service":
            body, ctype = json.dumps(register_service()).encode(), "application/json"
        elif path == "/cockpit_extras.json":
            body, ctype = json.dumps(cockpit_extras()).encode(), "application/json"
        elif path == "/health":
            body, ctype = json.dumps({"counts": dict(hub.counts, bad=hub.bad()), "pages": len(hub.clients),
                                      "silent_s": time.time() - hub.last_rx if hub.last_rx else None}).encode(), "application/json"
        else:
            return connection.respond(404, "not found\n")
        return Response(200, "OK", Headers([("Content-Type", ctype), ("Content-Length", str(len(body))),
                                            ("Cache-Control", "no-store")]), body)

    host, port = a.listen.rsplit(":", 1)
    # No per-message compression: beams are noisy bytes that deflate poorly, and it cost the server a tenth of its time.
    async with serve(lambda ws: handler(ws, hub), host, int(port), process_request=http, max_size=1 << 16,
                     ping_interval=5, ping_timeout=10, compression=None, create_connection=connection_class(hub)):
        print(f"sonar_view: http://{host}:{port}/ (LCM {a.lcm or 'default'}, prefix '{a.prefix}'; Cockpit: "
              f"/cockpit_extras.json)", file=sys.stderr, flush=True)
        asyncio.create_task(ticker(hub))
        # SIGTERM (systemd, BlueOS) and SIGINT end it cleanly, also where a shell started it with SIGINT ignored
        import signal
        stop = loop.create_future()
        for sig in (signal.SIGTERM, signal.SIGINT):
            loop.add_signal_handler(sig, lambda: stop.done() or stop.set_result(None))
        await stop


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lcm", default=os.environ.get("LCM_DEFAULT_URL"), help="LCM URL (default: LCM's own)")
    ap.add_argument("--listen", default="127.0.0.1:8360", help="ADDR:PORT to serve the page on")
    ap.add_argument("--prefix", default="", help="sonard's --channel-prefix")
    ap.add_argument("--types", default=os.environ.get("SONARD_LCM_PY", "build/lcm/python"),
                    help="directory holding the generated 'sonar' package")
    ap.add_argument("--still-alarm", type=float, default=float(os.environ.get("SONARD_STILL_ALARM", "60")),
                    help="seconds a track may stay still before the status widget raises its alarm (default 60)")
    a = ap.parse_args()
    try:
        asyncio.run(main_async(a))
    except KeyboardInterrupt:
        pass
    except OSError as e:
        raise SystemExit(f"sonar_view: --listen {a.listen}: {e.strerror}")


if __name__ == "__main__":
    main()
