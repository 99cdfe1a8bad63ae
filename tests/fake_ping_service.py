#!/usr/bin/env python3
"""fake_ping_service.py -- BlueOS's ping service as sonard meets it: GET /v1.0/sensors on 127.0.0.1:PORT answering
in one of several ways, and counting the asks (printed at exit, "asks N").
  good     a Ping1D (bridge 9090) and a serial Ping360 whose bridge is --bridge, as PingDeviceDescriptorModel lists them
  none     the Ping1D only
  garbage  a 200 with an HTML page; error: a 500; slow: accepts, then says nothing for 30 s
Usage: fake_ping_service.py --port P --mode MODE [--bridge 9092] [--seconds 60]"""
import argparse
import http.server
import json
import signal
import sys
import time

a = argparse.ArgumentParser()
a.add_argument("--port", type=int, required=True)
a.add_argument("--mode", choices=["good", "none", "garbage", "error", "slow"], required=True)
a.add_argument("--bridge", type=int, default=9092)
a.add_argument("--seconds", type=float, default=60)
o = a.parse_args()
asks = 0


def device(kind, port, udp):
    return {"ping_type": kind, "device_id": 2 if kind == "Ping360" else 1, "device_model": 2 if kind == "Ping360" else 1,
            "device_revision": 1, "firmware_version_major": 3, "firmware_version_minor": 3, "firmware_version_patch": 1,
            "port": port, "ethernet_discovery_info": "", "driver_status": {"udp_port": udp, "mavlink_driver_enabled": False}}


class H(http.server.BaseHTTPRequestHandler):
    def log_message(self, *args):
        pass

    def do_GET(self):
        global asks
        asks += 1
        if self.path != "/v1.0/sensors":
            self.send_error(404)
            return
        if o.mode == "slow":
            time.sleep(30)
            return
        if o.mode == "error":
            self.send_error(500)
            return
        if o.mode == "garbage":
            body = b"<html><body>Internal error</body></html>"
        else:
            devs = [device("Ping1D", "/dev/ttyUSB1", 9090)]
            if o.mode == "good":
                devs.append(device("Ping360", "/dev/ttyUSB0", o.bridge))
            body = json.dumps(devs).encode()
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)


class S(http.server.ThreadingHTTPServer):
    daemon_threads = True


srv = S(("127.0.0.1", o.port), H)
signal.signal(signal.SIGTERM, lambda *_: (print(f"asks {asks}", flush=True), sys.exit(0)))
srv.timeout = 0.2
end = time.time() + o.seconds
while time.time() < end:
    srv.handle_request()
print(f"asks {asks}", flush=True)
