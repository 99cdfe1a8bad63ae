#!/usr/bin/env python3
"""blueos_view_check.py -- the live view as BlueOS finds and shows it: GET / and /register_service as the helper asks
(services/helper/main.py: a 200 page with a title; a JSON object with the required string fields name, description,
icon, company, version, webpage, api, and optional route, new_page, extra_query, avoid_iframes,
works_in_relative_paths), then the page through a proxy under BlueOS's prefix /extensionv2/<name>/ (the page, its
script and its WebSocket by relative paths). Usage: blueos_view_check.py --url http://127.0.0.1:PORT/ [--vendor DIR].
Prints [  PASS  ]/[  FAIL  ] lines; exits 1 on a failure."""
import argparse
import asyncio
import http.client
import json
import re
import sys
import urllib.parse

ok = True


def check(cond, what):
    global ok
    print(f"[  {'PASS' if cond else 'FAIL'}  ] {what}", flush=True)
    ok &= bool(cond)
    return cond


def get(host, port, path, accept=None):
    c = http.client.HTTPConnection(host, port, timeout=5)
    c.request("GET", path, headers={"Accept": accept} if accept else {})
    r = c.getresponse()
    body = r.read()
    c.close()
    return r.status, r.getheader("Content-Type", ""), body


REQUIRED = ("name", "description", "icon", "company", "version", "webpage", "api")
OPTIONAL = {"route": str, "new_page": bool, "extra_query": str, "avoid_iframes": bool, "works_in_relative_paths": bool,
            "extras": dict, "sanitized_name": str}


async def prefix_proxy(view_host, view_port, prefix, local=None):
    """A TCP relay that strips prefix from the request line, as BlueOS's nginx does for /extensionv2/<name>/.
    local: {path: (status, content type, body)} answered by the proxy itself (BlueOS's own pages: the helper's
    web_services, a control station's page), looked up at each request, so a caller may add to it later."""
    async def serve(r, w):
        try:
            line = await r.readline()
            m = re.match(rb"(\S+) (\S+) (HTTP/\S+)\r\n", line)
            if m and local is not None and m.group(2).decode("latin-1").split("?")[0] in local:
                status, ctype, body = local[m.group(2).decode("latin-1").split("?")[0]]
                w.write(f"HTTP/1.1 {status} OK\r\nContent-Type: {ctype}\r\nContent-Length: {len(body)}\r\n"
                        f"Connection: close\r\n\r\n".encode() + body)
                await w.drain()
                w.close()
                return
            if not m or not m.group(2).startswith(prefix.encode()):
                w.write(b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\nConnection: close\r\n\r\n")
                await w.drain()
                w.close()
                return
            path = b"/" + m.group(2)[len(prefix):]
            ur, uw = await asyncio.open_connection(view_host, view_port)
            uw.write(m.group(1) + b" " + path + b" " + m.group(3) + b"\r\n")

            async def pipe(a, b):
                try:
                    while True:
                        d = await a.read(65536)
                        if not d:
                            break
                        b.write(d)
                        await b.drain()
                except (ConnectionError, asyncio.CancelledError):
                    pass
                finally:
                    b.close()
            await asyncio.gather(pipe(r, uw), pipe(ur, w))
        except ConnectionError:
            pass
    return await asyncio.start_server(serve, "127.0.0.1", 0)


async def through_proxy(host, port, name, cockpit=None):
    from websockets.asyncio.client import connect
    prefix = f"/extensionv2/{name}/"
    srv = await prefix_proxy(host, port, prefix)
    pport = srv.sockets[0].getsockname()[1]
    loop = asyncio.get_running_loop()
    status, _, page = await loop.run_in_executor(None, get, "127.0.0.1", pport, prefix)
    refs = re.findall(rb'(?:src|href)="([^"]*)"', page)
    check(status == 200 and refs and all(not r.startswith(b"/") and b"//" not in r for r in refs),
          f"the page under {prefix} (status {status}); its references are relative: {[r.decode() for r in refs]}")
    for r in refs:
        url = urllib.parse.urljoin(prefix, r.decode())
        s, ctype, body = await loop.run_in_executor(None, get, "127.0.0.1", pport, url)
        check(s == 200 and len(body) > 0, f"{url} through the proxy: {s}, {len(body)} bytes, {ctype}")
        if r.endswith(b".js"):
            check(b"new URL(\"ws\", location.href)" in body, "the script opens its WebSocket relative to the page")
    if cockpit:
        # Cockpit's widgets as it finds them (tests/cockpit_check.py follows the whole discovery): the extras JSON at
        # the service's base, each widget's page and icon under it
        s, _, body = await loop.run_in_executor(None, get, "127.0.0.1", pport, prefix.rstrip("/") + cockpit)
        try:
            widgets = json.loads(body).get("widgets", [])
        except ValueError:
            widgets = []
        urls = [prefix.rstrip("/") + w[k] for w in widgets for k in ("iframe_url", "iframe_icon")]
        got = [(await loop.run_in_executor(None, get, "127.0.0.1", pport, u))[0] for u in urls]
        check(s == 200 and widgets and all(g == 200 for g in got),
              f"Cockpit's extras {cockpit} through the proxy: {s}; its widgets' pages and icons: {dict(zip(urls, got))}")
    try:
        async with connect(f"ws://127.0.0.1:{pport}{prefix}ws", open_timeout=15) as ws:
            kinds = set()
            end = loop.time() + 15  # bounded; under qemu-user the image's view answers slowly
            while "view" not in kinds and loop.time() < end:
                m = await asyncio.wait_for(ws.recv(), timeout=end - loop.time())
                if isinstance(m, str):
                    kinds.add(json.loads(m).get("kind"))
        check("view" in kinds, f"the WebSocket {prefix}ws through the proxy streams the view's messages: {sorted(kinds)}")
    except Exception as e:
        check(False, f"the WebSocket {prefix}ws through the proxy: {e!r}")
    srv.close()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--url", required=True)
    ap.add_argument("--vendor", help="a directory holding websockets (the package's or image's vendor/)")
    a = ap.parse_args()
    if a.vendor:
        sys.path.insert(0, a.vendor)
    u = urllib.parse.urlparse(a.url)
    host, port = u.hostname, u.port
    status, ctype, body = get(host, port, "/")
    title = re.search(rb"<title>([^<]*)</title>", body)
    check(status == 200 and title, f"GET / answers 200 with a title, as the helper's scan wants: {status}, "
          f"{title.group(1).decode() if title else None}")
    status, ctype, body = get(host, port, "/register_service", "application/json")
    try:
        meta = json.loads(body)
    except ValueError:
        meta = None
    check(status == 200 and isinstance(meta, dict), f"GET /register_service: {status}, {ctype}, a JSON object")
    meta = meta if isinstance(meta, dict) else {}
    missing = [k for k in REQUIRED if not isinstance(meta.get(k), str)]
    wrong = [k for k, t in OPTIONAL.items() if k in meta and not isinstance(meta[k], t)]
    check(not missing and not wrong, f"the helper's ServiceMetadata parses it: required strings present "
          f"(missing {missing}), optional fields typed (wrong {wrong})")
    sanitized = re.sub(r"[^a-z0-9]", "", str(meta.get("name", "")).lower())
    check(sanitized and str(meta.get("icon", "")).startswith("mdi-") and
          re.fullmatch(r"\d+\.\d+\.\d+(?:[-+].*)?", str(meta.get("version", ""))) and meta.get("works_in_relative_paths") is True,
          f"name '{meta.get('name')}' (page at /extensionv2/{sanitized}/), icon {meta.get('icon')}, version "
          f"{meta.get('version')}, works_in_relative_paths {meta.get('works_in_relative_paths')}")
    asyncio.run(through_proxy(host, port, sanitized or "sonard", (meta.get("extras") or {}).get("cockpit")))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
