#!/usr/bin/env python3
"""cockpit_check.py -- sonard in Cockpit, end to end: a BlueOS stand-in (the helper's /helper/v1.0/web_services built
from the view's /register_service as the helper does, and nginx's /extensionv2/<name>/ prefix), Cockpit's discovery
followed step by step as src/libs/blueos.ts codes it, both widgets in Debian's headless chromium in 400x300 iframes
beside the full view, the actions pressed as Cockpit's http-request action sends them, against a simulated Ping360
(sonar-feed): a survey recorded, written and in use with no restart, a second press refused while it runs, the view
server restarted mid-survey, the alarms (a still track, a lost sonar), a survey refused when someone moves, malformed
requests refused with nothing changed, control off answered 403. Run by tests/cockpit.sh in a network namespace.
Prints [  PASS  ] / [  FAIL  ] lines and a JSON report (--report).
"""
import argparse
import asyncio
import json
import os
import re
import shlex
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.parse
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from blueos_view_check import prefix_proxy  # noqa: E402  the nginx stand-in, one place

rep = {"checks": {}}


def ok(name, cond, detail=""):
    rep["checks"][name] = bool(cond)
    print(("[  PASS  ] " if cond else "[  FAIL  ] ") + name + (f": {detail}" if detail else ""), flush=True)
    return cond


def wait_for(fn, timeout, step=0.25):
    end = time.time() + timeout
    while time.time() < end:
        v = fn()
        if v:
            return v
        time.sleep(step)
    return None


def http(method, url, body=None, headers=None, timeout=10):
    """(status, parsed JSON or text) of one request, errors included."""
    req = urllib.request.Request(url, data=body, method=method, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            code, data, ctype = r.status, r.read(), r.headers.get("Content-Type", "")
    except urllib.error.HTTPError as e:
        code, data, ctype = e.code, e.read(), e.headers.get("Content-Type", "")
    except (urllib.error.URLError, OSError) as e:
        return 0, {"error": str(e)}, ""
    if "json" in ctype:
        try:
            return code, json.loads(data), ctype
        except ValueError:
            pass
    return code, data, ctype


class StandIn:
    """BlueOS on one port: the helper's web_services and the extensions' /extensionv2/<name>/ proxy; a page of our own."""

    def __init__(self, view_port, name):
        self.local = {}
        self.loop = asyncio.new_event_loop()
        self.prefix = f"/extensionv2/{name}/"
        ready = threading.Event()

        def run():
            asyncio.set_event_loop(self.loop)
            self.srv = self.loop.run_until_complete(prefix_proxy("127.0.0.1", view_port, self.prefix, self.local))
            ready.set()
            self.loop.run_forever()
        threading.Thread(target=run, daemon=True).start()
        ready.wait(10)
        self.port = self.srv.sockets[0].getsockname()[1]
        self.addr = f"127.0.0.1:{self.port}"

    def web_services(self, view_port):
        """As BlueOS's helper lists a service it found listening: its port, path, and /register_service's metadata
        with the sanitized_name the helper adds (services/helper/main.py)."""
        code, meta, _ = http("GET", f"http://127.0.0.1:{view_port}/register_service")
        meta = dict(meta) if isinstance(meta, dict) else {}
        meta["sanitized_name"] = re.sub(r"[^a-z0-9]", "", meta.get("name", "").lower())
        services = [{"title": "sonard view", "documentation_url": "", "versions": [], "port": view_port, "path": "/",
                     "metadata": meta},
                    {"title": "an extension without extras", "documentation_url": "", "versions": [], "port": 9,
                     "path": "/", "metadata": {"name": "Other", "sanitized_name": "other"}}]
        self.local["/helper/v1.0/web_services"] = (200, "application/json", json.dumps(services).encode())


HTTP_METHODS = ("GET", "POST", "PUT", "DELETE", "PATCH")  # Cockpit's HttpRequestMethod


def discover(addr):
    """Cockpit's discovery (src/libs/blueos.ts: getServicesFromBlueOS, blueOsServiceUrl, getExtrasJsonFromBlueOsService,
    getWidgetsFromBlueOS, getActionsFromBlueOS): each step checked, every field Cockpit reads required."""
    code, services, _ = http("GET", f"http://{addr}/helper/v1.0/web_services")
    ok("discovery: GET /helper/v1.0/web_services is a JSON list of services", code == 200 and isinstance(services, list),
       f"{code}, {len(services) if isinstance(services, list) else services!r:.80} services")
    widgets, actions = [], []
    for svc in services if isinstance(services, list) else []:
        md = svc.get("metadata") or {}
        cockpit = (md.get("extras") or {}).get("cockpit")
        if cockpit is None:
            continue
        base = (f"http://{addr}/extensionv2/{md.get('sanitized_name')}" if md.get("works_in_relative_paths")
                else f"http://{addr.split(':')[0]}:{svc.get('port')}")
        code, extras, ctype = http("GET", base + cockpit)
        ok(f"discovery: {md.get('name')}: metadata.extras.cockpit '{cockpit}' fetched from the service's base {base}",
           code == 200 and isinstance(extras, dict), f"{code} {ctype}")
        if not isinstance(extras, dict):
            continue
        ok("discovery: the extras JSON: target_system 'cockpit', target_cockpit_api_version a version, widgets and "
           "actions lists", extras.get("target_system") == "cockpit" and
           re.fullmatch(r"\d+\.\d+\.\d+", str(extras.get("target_cockpit_api_version", ""))) and
           isinstance(extras.get("widgets"), list) and isinstance(extras.get("actions"), list),
           f"{extras.get('target_system')}, {extras.get('target_cockpit_api_version')}")
        for w in extras.get("widgets", []):
            fields = all(isinstance(w.get(k), str) and w.get(k) for k in ("name", "iframe_url", "iframe_icon", "version"))
            fields &= "config_iframe_url" in w and (w["config_iframe_url"] is None or isinstance(w["config_iframe_url"], str))
            url, icon = base + w.get("iframe_url", ""), base + w.get("iframe_icon", "")
            c1, page, t1 = http("GET", url)
            c2, img, t2 = http("GET", icon)
            ok(f"discovery: widget '{w.get('name')}': name, iframe_url, iframe_icon, config_iframe_url, version; page "
               f"{url} and icon {icon} load", fields and c1 == 200 and "text/html" in t1 and c2 == 200 and
               t2.startswith("image/") and len(img) > 0, f"page {c1} {t1}, icon {c2} {t2}")
            widgets.append(dict(w, iframe_url=url, iframe_icon=icon))
        for a in extras.get("actions", []):
            c = a.get("config") or {}
            good = (all(isinstance(a.get(k), str) and a.get(k) for k in ("id", "name")) and
                    a.get("type") in ("http-request", "mavlink-message", "javascript"))
            if a.get("type") == "http-request":
                good &= (isinstance(c.get("name"), str) and isinstance(c.get("url"), str) and c.get("method") in HTTP_METHODS
                         and isinstance(c.get("headers"), dict) and isinstance(c.get("urlParams"), dict) and
                         isinstance(c.get("body"), str))
            ok(f"discovery: action '{a.get('id')}' ({a.get('type')}): id, name, type and an http-request config (name, url, "
               f"method, headers, urlParams, body)", good, f"{c.get('method')} {c.get('url')} {c.get('urlParams')}")
            actions.append(a)
    return widgets, actions


def press(action, addr, params=None, method=None, body=None):
    """An http-request action as Cockpit runs it (src/libs/actions/http-request.ts): data-lake inputs ({{ id }}) in the
    URL replaced (vehicle-address: the vehicle), urlParams merged into the URL's query, the method, the headers,
    the body unless GET. params, method and body override the action's, for the malformed requests."""
    c = action["config"]
    url = re.sub(r"{{\s*vehicle-address\s*}}", addr, c["url"])
    u = urllib.parse.urlsplit(url)
    q = dict(urllib.parse.parse_qsl(u.query))
    q.update(c["urlParams"] if params is None else params)
    url = urllib.parse.urlunsplit((u.scheme, u.netloc, u.path, urllib.parse.urlencode(q), ""))
    m = method or c["method"]
    data = None if m == "GET" else (c["body"] if body is None else body).encode()
    return http(m, url, data, c["headers"])


def proc_cpu_s(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--tmp", required=True)
    ap.add_argument("--lcm", required=True)
    ap.add_argument("--report", required=True)
    ap.add_argument("--shot", required=True)
    ap.add_argument("--view-python", default=sys.executable, help="the Python with websockets (the view's venv)")
    a = ap.parse_args()
    B, T = a.build, a.tmp
    survey = os.path.join(T, "site.sv")
    feed_port, view_port = 5470, 8361
    logs = open(os.path.join(T, "procs.err"), "w")

    def feed(empty):
        # The empty site at 8 times a Ping360's pace (its survey in 20 s); the occupied pool at twice it, the swimmers
        # on the wall clock: 1.9 m a look at 0.6 m/s (a Ping360's 6.3 s turns: 3.8 m; sonar-feed's default 10 s of scene
        # a sweep at x8 would make it 6 m, more than the tracker follows: then nothing refuses a survey, see docs/blueos.md).
        pace = ["--pace", "x8"] if empty else ["--pace", "x2", "--scene-clock", "wall"]
        return subprocess.Popen([f"{B}/sonar-feed", "--listen", f"tcp:127.0.0.1:{feed_port}", "--scene", "laps", "--seed", "5",
                                 "--max-seconds", "400"] + pace + (["--empty"] if empty else []),
                                stdout=subprocess.DEVNULL, stderr=logs)

    def sonard(control=True):
        return subprocess.Popen([f"{B}/sonard", "--sonar", f"tcp:127.0.0.1:{feed_port}", "--range", "15", "--samples", "600",
                                 "--step", "4", "--lcm", a.lcm, "--quiet", "--survey", survey] +
                                (["--control"] if control else []), stdout=subprocess.DEVNULL,
                                stderr=open(os.path.join(T, "sonard.err"), "a"))

    def view():
        return subprocess.Popen([a.view_python, "tools/view/sonar_view.py", "--lcm", a.lcm, "--listen",
                                 f"127.0.0.1:{view_port}", "--types", f"{B}/lcm/python", "--still-alarm", "4"],
                                stdout=subprocess.DEVNULL, stderr=open(os.path.join(T, "view.err"), "a"))

    def status():
        code, h, _ = http("GET", f"http://127.0.0.1:{view_port}/health")
        return h if code == 200 else None

    procs = {"feed": feed(True)}
    time.sleep(0.3)
    procs["sonard"], procs["view"] = sonard(), view()
    drv = None
    try:
        wait_for(lambda: http("GET", f"http://127.0.0.1:{view_port}/register_service")[0] == 200, 10)
        blueos = StandIn(view_port, "sonard")
        blueos.web_services(view_port)
        widgets, actions = discover(blueos.addr)
        names = sorted(w["name"] for w in widgets)
        ids = sorted(x["id"] for x in actions)
        rep["discovered"] = {"widgets": [{k: w[k] for k in ("name", "iframe_url", "iframe_icon")} for w in widgets],
                             "actions": [{"id": x["id"], "name": x["name"], "method": x["config"]["method"],
                                          "url": x["config"]["url"], "urlParams": x["config"]["urlParams"]} for x in actions]}
        ok("Cockpit's discovery finds both widgets and both actions from the extension's metadata alone",
           len(widgets) == 2 and ids == ["sonard-cancel-survey", "sonard-record-survey"], f"widgets {names}, actions {ids}")
        act = {x["id"]: x for x in actions}
        record, cancel = act.get("sonard-record-survey"), act.get("sonard-cancel-survey")
        fan = next(w for w in widgets if "fan" in w["iframe_url"])
        tile = next(w for w in widgets if "status" in w["iframe_url"])

        # Cockpit's place for them: 400 x 300 tiles, and the full view beside them (the server's third page).
        host = f"""<!doctype html><title>cockpit stand-in</title><body style="margin:0;background:#222">
<iframe id="fan" src="{fan['iframe_url']}" width="400" height="300" style="border:0"></iframe>
<iframe id="status" src="{tile['iframe_url']}" width="400" height="300" style="border:0"></iframe>
<iframe id="full" src="http://{blueos.addr}/extensionv2/sonard/" width="1120" height="760" style="border:0"></iframe>"""
        blueos.local["/cockpit.html"] = (200, "text/html; charset=utf-8", host.encode())
        from view_check import chromium
        drv = chromium("1920,1100")

        def in_frame(fid, script, *args):
            drv.switch_to.default_content()
            drv.switch_to.frame(drv.find_element("id", fid))
            try:
                return drv.execute_script(script, *args)
            finally:
                drv.switch_to.default_content()
        drv.get(f"http://{blueos.addr}/cockpit.html")
        wait_for(lambda: in_frame("fan", "return window.sonarView && sonarView.beams > 100") and
                 in_frame("status", "return window.sonarStatus && sonarStatus.beamsPerS != null"), 30)
        cpu0, t0 = proc_cpu_s(procs["view"].pid), time.time()
        f0 = in_frame("fan", "sonarView.resetStats(); return sonarView.frames")
        fb0, vb0 = in_frame("fan", "return sonarView.beams"), in_frame("full", "return sonarView.beams")
        sb0 = (status() or {}).get("counts", {}).get("beams", 0)
        time.sleep(10)
        cpu1, t1 = proc_cpu_s(procs["view"].pid), time.time()
        fb1, vb1 = in_frame("fan", "return sonarView.beams"), in_frame("full", "return sonarView.beams")
        sb1 = (status() or {}).get("counts", {}).get("beams", 0)
        rates = [(x1 - x0) / (t1 - t0) for x0, x1 in ((sb0, sb1), (fb0, fb1), (vb0, vb1))]
        rep["beam_rates"] = {"server_in": rates[0], "fan_tile": rates[1], "full_view": rates[2]}
        ok("the fan tile and the full view draw new beams at the sonar's rate (within 5 %) with the status tile open",
           rates[0] > 20 and min(rates[1:]) >= 0.95 * rates[0],
           "%.1f beams/s reach the view server, %.1f drawn by the fan tile, %.1f by the full view" % tuple(rates))
        fanv = in_frame("fan", """const d = document.getElementById('image').getContext('2d').getImageData(0, 0, 720, 720).data;
            let lit = 0, drawn = 0;
            for (let i = 0; i < d.length; i += 4) {
              if (!(d[i] === 0x10 && d[i + 1] === 0x14 && d[i + 2] === 0x1a)) drawn++;
              if (d[i] + d[i + 1] + d[i + 2] > 150) lit++; }
            const r = document.getElementById('fan').getBoundingClientRect();
            return {first: sonarView.firstDrawMs, beams: sonarView.beams, frames: sonarView.frames, drawn, lit,
                    w: r.width, h: r.height, iw: innerWidth, ih: innerHeight};""")
        st = in_frame("status", "return {first: sonarStatus.firstStatusMs, rows: sonarStatus.rows, alarms: sonarStatus.alarms, bps: sonarStatus.beamsPerS}")
        fps = (fanv["frames"] - f0) / (t1 - t0)
        rep["fan"], rep["status_tile"] = dict(fanv, fps=fps), st
        ok("the fan widget at 400x300: drawn within 2 s of loading; the fan fits the tile; beams and the pool's walls drawn",
           fanv["first"] is not None and fanv["first"] <= 2000 and fanv["iw"] == 400 and fanv["ih"] == 300 and
           fanv["w"] <= 400 and fanv["h"] <= 300 and fanv["drawn"] > 100000 and fanv["lit"] > 200,
           f"first frame {fanv['first']:.0f} ms after load, {fanv['drawn']} of 518400 canvas pixels drawn (not background), "
           f"{fanv['lit']} bright, {fps:.1f} frames/s, {fanv['beams']} beams")
        ok("the status widget at 400x300: its first status within 2 s of loading; link, beams/s, nearest object, objects, "
           "stillest track, survey", st["first"] is not None and st["first"] <= 2000 and st["bps"] and st["bps"] > 5 and
           all(k in st["rows"] for k in ("link", "beams / s", "nearest object", "objects / tracks", "stillest track", "survey"))
           and st["rows"]["survey"].startswith("none"), f"{st['first']:.0f} ms; {st['rows']}")
        shot_dir = os.path.dirname(a.shot)
        drv.save_screenshot(a.shot)
        # The view server's CPU with the two tiles and the full view open, at the sonar's rate (here x8 a Ping360's).
        share = 100 * (cpu1 - cpu0) / (t1 - t0)
        rep["view_cpu"] = {"percent_of_this_core": share, "beams_s": st["bps"]}
        print(f"cockpit: view server CPU with two tiles and the full view open: {share:.1f} % of one core here at "
              f"{st['bps']:.0f} beams/s", flush=True)

        # Malformed requests: refused with a status, nothing sent to sonard.
        seq0 = (http("GET", f"http://127.0.0.1:{view_port}/health")[1] or {})
        bad = {"GET (a command is a POST)": (press(record, blueos.addr, method="GET"), 405),
               "a body of 4 KiB": (press(record, blueos.addr, body="x" * 4096), 413),
               "sweeps=7": (press(record, blueos.addr, params={"sweeps": "7"}), 400),
               "sweeps=many": (press(record, blueos.addr, params={"sweeps": "many"}), 400),
               "an unknown command": (http("POST", f"http://{blueos.addr}/extensionv2/sonard/control/format", b""), 404)}
        rep["malformed"] = {k: [v[0][0], v[0][1]] for k, v in bad.items()}
        ok("malformed control requests refused with a status: " + ", ".join(f"{k} {v[0][0]}" for k, v in bad.items()),
           all(v[0][0] == v[1] for v in bad.values()), json.dumps({k: v[0][1] for k, v in bad.items()})[:400])

        # The survey, from the action, on the empty site.
        code, ans, _ = press(record, blueos.addr)
        ok("the record action: taken, and said (sonard's answer on SONAR_STATUS)", code == 200 and ans.get("taken") and
           ans.get("survey_rec") == 1, f"{code} {ans}")
        time.sleep(1.2)
        code2, ans2, _ = press(record, blueos.addr)
        ok("a second survey while one is recorded: refused, 409, why said", code2 == 409 and "being recorded" in
           ans2.get("control_said", ""), f"{code2} {ans2.get('control_said')}")
        # The view server restarted mid-survey: sonard records on; the pages come back by themselves.
        procs["view"].terminate()
        procs["view"].wait(10)
        procs["view"] = view()
        done = wait_for(lambda: in_frame("status", "return sonarStatus.status && sonarStatus.status.survey_rec >= 2 && sonarStatus.status"), 90)
        spid = procs["sonard"].pid
        ok("the survey started from the action completes with the view server restarted midway; written, loaded and in "
           "use with no restart of sonard", done and done["survey_rec"] == 2 and done["survey_state"] == 1 and
           done["survey_fixed"] == 1 and done["survey_sweeps"] >= 20 and os.path.getsize(survey) > 1000 and
           procs["sonard"].poll() is None and not [f for f in os.listdir(T) if ".tmp." in f],
           f"{done and done['survey_rec_said']}; file {os.path.getsize(survey) if os.path.exists(survey) else 0} bytes, sonard pid {spid} running")
        rows = wait_for(lambda: (lambda r: "written" in r.get("survey", "") and r)(in_frame("status", "return sonarStatus.rows")), 5) or \
            in_frame("status", "return sonarStatus.rows")
        ok("the status widget says the survey is in use and the recording's end", "in use" in rows.get("survey", "") and
           "written" in rows.get("survey", ""), rows.get("survey"))
        survey_bytes = open(survey, "rb").read()

        # The pool fills: the feed now serves swimmers and a stander; sonard reconnects by itself.
        procs["feed"].terminate()
        procs["feed"].wait(10)
        procs["feed"] = feed(False)
        alarm = wait_for(lambda: [x for x in in_frame("status", "return sonarStatus.alarms") if x.startswith("STILL")], 60)
        trk = in_frame("status", "return sonarStatus.tracks")
        ok("a track still longer than --still-alarm (4 s here) raises the still alarm in the status widget (the stander, "
           "against the survey)", alarm, f"{alarm}; tracks {[(t['id'], t['what'], round(t['still_s'])) for t in trk]}")
        # One sweep's detections can hold a single swimmer (two passing close merge, one at the edge of range), so
        # the widget is watched over a few sweeps for the most it draws at once.
        seen = []
        objs = wait_for(lambda: (lambda n: seen.append(n) or (n if n >= 2 else None))(
            in_frame("fan", "return sonarView.detections.filter(d => !d.structure).length")), 10) or 0
        ok("the fan widget draws the swimmers' detections against the survey", objs >= 2,
           f"{objs} objects (counts seen: {seen[:12]})")
        # What each is doing, as sonard says on SONAR_TRACKS (docs/activity.md): swimmers moving, the stander standing.
        acts = wait_for(lambda: (lambda a: a if {"moving", "standing"} <= a else None)(
            {t.get("activity") for t in in_frame("status", "return sonarStatus.tracks")}), 90)
        row = wait_for(lambda: (lambda r: r if re.search(r"[1-9]\d* standing", r.get("activity", "")) else None)(
            in_frame("status", "return sonarStatus.rows")), 20) or in_frame("status", "return sonarStatus.rows")
        ok("sonard's activity reaches the status widget: the swimmers moving, the stander standing "
           f"(its row: {row.get('activity')})", acts and re.search(r"[1-9]\d* standing", row.get("activity", "")),
           f"{acts}; tracks {[(t['id'], t.get('activity'), t.get('echo_corr')) for t in in_frame('status', 'return sonarStatus.tracks')]}")
        drv.save_screenshot(os.path.join(shot_dir, "cockpit-occupied.png"))

        # A survey pressed while people swim: refused, why said, the survey in use kept.
        time.sleep(1.2)
        code, ans, _ = press(record, blueos.addr)
        refused = wait_for(lambda: in_frame("status", "return sonarStatus.status && sonarStatus.status.survey_rec === 3 && sonarStatus.status"), 90)
        rows = wait_for(lambda: (lambda r: "refused" in r.get("survey", "") and r)(in_frame("status", "return sonarStatus.rows")), 5) or \
            in_frame("status", "return sonarStatus.rows")
        ok("a survey recorded while someone moves: refused, why said in the widget, the file and the survey in use kept",
           code == 200 and refused and "went" in refused["survey_rec_said"] and "refused" in rows.get("survey", "") and
           open(survey, "rb").read() == survey_bytes and refused["survey_state"] == 1,
           f"{refused and refused['survey_rec_said']}; widget: {rows.get('survey')}")
        # Cancel with nothing recorded: refused (409), nothing changed.
        time.sleep(1.2)
        code, ans, _ = press(cancel, blueos.addr)
        ok("cancel with no survey being recorded: refused, 409, said", code == 409 and "no survey" in ans.get("control_said", ""),
           f"{code} {ans.get('control_said')}")
        # The sonar lost: the alarm.
        procs["feed"].terminate()
        procs["feed"].wait(10)
        lost = wait_for(lambda: [x for x in in_frame("status", "return sonarStatus.alarms") if x.startswith("SONAR LOST")], 20)
        ok("the sonar lost: the status widget's alarm", lost, f"{lost}")
        procs["feed"] = feed(True)
        # Control off: sonard without --control; the action answers 403 and says how to turn it on.
        procs["sonard"].send_signal(2)
        procs["sonard"].wait(15)
        procs["sonard"] = sonard(control=False)
        wait_for(lambda: (status() or {}).get("silent_s") is not None and status()["silent_s"] < 1 and
                 in_frame("status", "return sonarStatus.status && sonarStatus.status.control === 0"), 30)
        code, ans, _ = press(record, blueos.addr)
        ok("control off (sonard without --control): the action answers 403 and says how to enable it",
           code == 403 and "--control" in ans.get("error", ""), f"{code} {ans}")
    finally:
        if drv is not None:
            drv.quit()
        for p in procs.values():
            if p.poll() is None:
                p.send_signal(2)
                try:
                    p.wait(10)
                except subprocess.TimeoutExpired:
                    p.kill()
    json.dump(rep, open(a.report, "w"), indent=1)
    sys.exit(0 if rep["checks"] and all(rep["checks"].values()) else 1)


if __name__ == "__main__":
    main()
