#!/usr/bin/env python3
"""view_check.py -- drives Debian's chromium (selenium, headless) against sonar_view.py while sonard runs a live
sonar-feed: the known objects show as bright pixels where they are, the page keeps updating, it says when sonard is
gone and recovers when sonard is back, malformed LCM messages are counted, a page opened mid-sweep draws. Writes a
screenshot and a JSON report. Run by tests/view.sh inside a network namespace of its own.

  view_check.py --url URL --truth pool.json --sonard "CMD..." --bad-cmd "CMD..." --shot view.png --report r.json
"""
import argparse
import json
import shlex
import subprocess
import sys
import time

from selenium import webdriver
from selenium.webdriver.chrome.service import Service


def chromium(size):
    """Debian's chromium, headless, driven by its chromedriver, its window W,H pixels (also tests/cockpit_check.py's)."""
    opts = webdriver.ChromeOptions()
    opts.binary_location = "/usr/bin/chromium"
    for o in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", f"--window-size={size}",
              "--no-first-run", "--disable-extensions", "--disable-background-networking"):
        opts.add_argument(o)
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)


def wait_for(what, fn, timeout):
    end = time.time() + timeout
    while time.time() < end:
        v = fn()
        if v:
            return v
        time.sleep(0.25)
    raise SystemExit(f"view_check: timed out after {timeout} s waiting for {what}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--url", required=True)
    ap.add_argument("--truth", required=True)
    ap.add_argument("--sonard", required=True, help="the sonard command line to start (and restart)")
    ap.add_argument("--sonard-fast", help="sonard against a sonar-feed at --pace fast: the overload phase")
    ap.add_argument("--health", help="the view server's /health URL")
    ap.add_argument("--bad-cmd", required=True, help="a command that publishes malformed LCM messages")
    ap.add_argument("--shot", required=True)
    ap.add_argument("--report", required=True)
    ap.add_argument("--sweep-s", type=float, default=7.0, help="a sweep's length, seconds (waits are scaled by it)")
    a = ap.parse_args()
    rep = {"checks": {}}

    def ok(name, cond, detail=""):
        rep["checks"][name] = bool(cond)
        print(("[  PASS  ] " if cond else "[  FAIL  ] ") + name + (f": {detail}" if detail else ""), flush=True)

    drv = chromium("1120,800")
    js = drv.execute_script
    sonard = subprocess.Popen(shlex.split(a.sonard), stdout=subprocess.DEVNULL, stderr=open(a.report + ".sonard.err", "w"))
    try:
        time.sleep(1.0)  # the page is opened after sonard started: mid-sweep
        drv.get(a.url)
        wait_for("the first beams", lambda: js("return window.sonarView && window.sonarView.beams > 5"), 20)
        b0 = js("return window.sonarView.beams")
        # one sweep and a bit: every angle drawn once
        time.sleep(a.sweep_s * 1.3)
        v = js("return {beams: sonarView.beams, frames: sonarView.frames, range: sonarView.range, status: sonarView.status}")
        ok("a page opened mid-sweep draws beams as they come", v["beams"] > b0 + 50, f"{b0} -> {v['beams']} beams")
        ok("the status panel has the link (scanning), the firmware and the sweep time",
           v["status"] is not None and v["status"]["link_state"] in (3, 4) and v["status"]["fw_major"] == 3
           and "firmware" in drv.page_source and "sweep time" in drv.page_source, json.dumps(v["status"])[:200])
        truth = json.load(open(a.truth))
        # the scene's objects appear in its 3rd and 4th sweeps (the background learns the pool first)
        want = max(i for i, sw in enumerate(truth["sweeps"]) if sw["objects"] and i <= 3)
        wait_for(f"sweep {want} to be over", lambda: js("return sonarView.status && sonarView.status.sweeps > arguments[0]", want),
                 a.sweep_s * (want + 3))
        objs = truth["sweeps"][want]["objects"]

        def brightness(x, y, half=3):
            return js("""const [u, v] = sonarView.toPixel(arguments[0], arguments[1]), h = arguments[2];
                         const d = document.getElementById('image').getContext('2d').getImageData(u - h, v - h, 2 * h + 1, 2 * h + 1).data;
                         let m = 0; for (let i = 0; i < d.length; i += 4) m = Math.max(m, d[i] + d[i + 1] + d[i + 2]); return m;""",
                      x, y, half)
        at_obj = [brightness(o["x"], o["y"]) for o in objs]
        # halfway from the sonar to each object: open water, dark
        between = [brightness(o["x"] * 0.5, o["y"] * 0.5, 1) for o in objs]
        rep["object_brightness"], rep["water_brightness"] = at_obj, between
        ok("each known object shows as bright pixels where it is, the water between is dark",
           objs and min(at_obj) >= 300 and max(between) < 200, f"objects {at_obj}, water {between}")
        trk = js("return sonarView.tracks")
        ok("the tracks on SONAR_TRACKS reach the page saying what each is and does (new, moving, resting, structure or "
           "static since start; moving, turning or resting)",
           trk and all(t.get("what") in ("new", "moving", "resting", "still", "static since start") and
                       t.get("mode") in ("moving", "turning", "resting") for t in trk), json.dumps(trk)[:300])
        sv = js("return document.getElementById('survey').textContent")
        ok("with no survey loaded, the page says so: 'no survey: learning'", sv == "no survey: learning", repr(sv))
        cm = js("return sonarView.clutter && {bands: sonarView.clutter.bands, sectors: sonarView.clutter.sectors, "
                "n: sonarView.clutter.density.length, looks: sonarView.clutter.looks, "
                "taught: new Set(sonarView.clutter.density.filter(d => d > 0)).size}")
        ok("the clutter map (SONAR_CLUTTER) reaches the page: every cell, looks taken",
           cm is not None and cm["n"] == cm["bands"] * cm["sectors"] and cm["looks"] > 0, json.dumps(cm))
        violet = """const d = document.getElementById('overlay').getContext('2d').getImageData(0, 0, 720, 720).data;
                   let n = 0; for (let i = 0; i < d.length; i += 4)
                     if (d[i + 3] > 0 && d[i] > 200 && d[i + 1] < 100 && d[i + 2] > 200) n++;
                   return n;"""
        off = js(violet)
        drv.find_element("id", "clutter").click()
        time.sleep(0.5)
        on = js(violet)
        drv.find_element("id", "clutter").click()
        ok("the clutter layer: off by default, switched on it shades the map's cells (violet pixels)",
           off == 0 and on > 0, f"{off} -> {on} violet pixels, {cm['taught']} densities among the cells")
        c1 = js("return document.getElementById('image').toDataURL()")
        f1 = js("return sonarView.frames")
        time.sleep(2.0)
        c2 = js("return document.getElementById('image').toDataURL()")
        f2 = js("return sonarView.frames")
        ok("the fan keeps updating (frames drawn, the image changes)", f2 > f1 + 10 and c2 != c1,
           f"frames {f1} -> {f2}")
        st = js("return sonarView.stats")
        rep["fps"], rep["latency_ms_mean"], rep["latency_ms_max"] = st["fps"], st["latency_ms_mean"], st["latency_ms_max"]
        ok("it keeps up with the device-paced sonar: latency behind the sonar under 250 ms",
           st["latency_ms_mean"] is not None and st["latency_ms_mean"] < 250,
           f"{st['fps']} frames/s, latency mean {st['latency_ms_mean']:.1f} ms, max {st['latency_ms_max']:.1f} ms")
        drv.save_screenshot(a.shot)
        # switched to SONAR_BEAM_FILTERED: the fan is redrawn from the foreground beams, mostly dark water
        b_raw = js("return sonarView.beams")
        drv.find_element("id", "filtered").click()
        time.sleep(a.sweep_s * 1.1)
        dark = js("""const d = document.getElementById('image').getContext('2d').getImageData(0, 0, 720, 720).data;
                     let n = 0, lit = 0; for (let i = 0; i < d.length; i += 4) { n++; if (d[i] + d[i + 1] + d[i + 2] > 150) lit++; }
                     return lit / n;""")
        ok("the filtered switch: SONAR_BEAM_FILTERED drawn instead, the background gone (under 2 % of pixels lit)",
           js("return sonarView.beams") > b_raw + 50 and dark < 0.02, f"{100 * dark:.2f} % lit")
        drv.find_element("id", "filtered").click()
        # malformed LCM messages on the view's channels: counted, the view goes on
        subprocess.run(shlex.split(a.bad_cmd), check=True)
        wait_for("the malformed messages to be counted", lambda: js("return (sonarView.viewInfo || {}).bad >= 3"), 5)
        b1 = js("return sonarView.beams")
        time.sleep(1.5)
        ok("malformed LCM messages are counted and skipped; the beams keep coming",
           js("return sonarView.beams") > b1 + 5, f"bad {js('return sonarView.viewInfo.bad')}")
        # sonard restarted: the page says it is gone, then resumes by itself
        sonard.send_signal(2)
        sonard.wait(timeout=10)
        wait_for("the page to say sonard is silent", lambda: "no data from sonard" in js("return document.getElementById('state').textContent"), 10)
        ok("sonard stopped: the page says so", True, js("return document.getElementById('state').textContent"))
        b2 = js("return sonarView.beams")
        sonard = subprocess.Popen(shlex.split(a.sonard), stdout=subprocess.DEVNULL, stderr=open(a.report + ".sonard2.err", "w"))
        wait_for("beams after the restart", lambda: js("return sonarView.beams") > b2 + 20, 20)
        wait_for("the page to say live again", lambda: "live" == js("return document.getElementById('state').textContent"), 10)
        ok("sonard restarted: the same page draws again and says live", True, f"{js('return sonarView.beams') - b2} beams since")
        if a.sonard_fast:
            # Overload: a sonar hundreds of times faster than the device. The view must drop, not queue.
            import urllib.request
            sonard.send_signal(2)
            sonard.wait(timeout=10)
            sonard = subprocess.Popen(shlex.split(a.sonard_fast), stdout=subprocess.DEVNULL,
                                      stderr=open(a.report + ".sonard3.err", "w"))
            time.sleep(2.0)
            h0 = json.load(urllib.request.urlopen(a.health))["counts"]
            p0 = js("sonarView.resetStats(); return sonarView.beams")
            t0 = time.time()
            time.sleep(6.0)
            dt = time.time() - t0
            h1 = json.load(urllib.request.urlopen(a.health))["counts"]
            p1 = js("return sonarView.beams")
            st = js("return sonarView.stats")
            rep["overload"] = {"server_beams_s": (h1["beams"] - h0["beams"]) / dt, "page_beams_s": (p1 - p0) / dt,
                               "dropped": h1["dropped"] - h0["dropped"], "fps": st["fps"],
                               "latency_ms_mean": st["latency_ms_mean"], "latency_ms_max": st["latency_ms_max"]}
            o = rep["overload"]
            ok("overloaded (sonar-feed --pace fast): beams dropped, not queued; latency stays under 250 ms",
               o["dropped"] > 0 and o["latency_ms_mean"] is not None and o["latency_ms_mean"] < 250,
               "%.0f beams/s in, %.0f drawn, %d dropped, %d frames/s, latency mean %.0f ms max %.0f ms" % (
                   o["server_beams_s"], o["page_beams_s"], o["dropped"], o["fps"], o["latency_ms_mean"] or -1,
                   o["latency_ms_max"] or -1))
    finally:
        if sonard.poll() is None:
            sonard.send_signal(2)
            try:
                sonard.wait(timeout=10)
            except subprocess.TimeoutExpired:
                sonard.kill()
        drv.quit()
    json.dump(rep, open(a.report, "w"), indent=1)
    sys.exit(0 if all(rep["checks"].values()) else 1)


if __name__ == "__main__":
    main()
