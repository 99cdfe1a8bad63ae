#!/usr/bin/env python3
"""bridge.py -- a relay like BlueOS's `bridges -u 0.0.0.0:PORT -p DEVICE` for the passive-mode tests: the sonar (here
sonar-feed on UDP) on one side; on the other, up to --clients UDP clients (5, as bridges keeps), each known once it
has sent a datagram. Every byte from the sonar goes to every known client; every client's bytes go to the sonar.
--forget S drops a client silent for S seconds (bridges without --no-udp-disconnection). At exit it writes --report
JSON: per client, the bytes and the Ping Protocol messages it sent, by id (how the test sees that a passive sonard
sent nothing that moves the head).
Usage: bridge.py --listen 127.0.0.1:9092 --sonar 127.0.0.1:5360 [--forget S] [--seconds N] --report FILE"""
import argparse
import json
import os
import selectors
import signal
import socket
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ping import Parser  # noqa: E402


def addr(s):
    h, p = s.rsplit(":", 1)
    return h, int(p)


def main():
    a = argparse.ArgumentParser()
    a.add_argument("--listen", required=True)
    a.add_argument("--sonar", required=True)
    a.add_argument("--clients", type=int, default=5)
    a.add_argument("--forget", type=float, default=0)
    a.add_argument("--seconds", type=float, default=60)
    a.add_argument("--report", required=True)
    o = a.parse_args()
    down = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    down.bind(addr(o.listen))
    up = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    up.connect(addr(o.sonar))
    sel = selectors.DefaultSelector()
    sel.register(down, selectors.EVENT_READ, "down")
    sel.register(up, selectors.EVENT_READ, "up")
    clients = {}   # addr -> last heard
    stats = {}     # "host:port" -> {"bytes", "datagrams", "ids": {id: count}, "parser"}
    forgotten = refused = relayed = 0
    end = [time.time() + o.seconds]
    signal.signal(signal.SIGTERM, lambda *_: end.__setitem__(0, 0))  # stop, and still write the report
    while time.time() < end[0]:
        for key, _ in sel.select(timeout=0.1):
            if key.data == "down":
                data, peer = down.recvfrom(65536)
                if peer not in clients and len(clients) >= o.clients:
                    refused += 1
                    continue
                clients[peer] = time.time()
                st = stats.setdefault(f"{peer[0]}:{peer[1]}", {"bytes": 0, "datagrams": 0, "ids": {}, "p": Parser()})
                st["bytes"] += len(data)
                st["datagrams"] += 1
                for mid, _ in st["p"].feed(data):
                    st["ids"][str(mid)] = st["ids"].get(str(mid), 0) + 1
                up.send(data)
            else:
                data = up.recv(65536)
                relayed += len(data)
                for c in list(clients):
                    down.sendto(data, c)
        if o.forget > 0:
            now = time.time()
            for c, t in list(clients.items()):
                if now - t > o.forget:
                    del clients[c]
                    forgotten += 1
    for st in stats.values():
        st["bad"] = st.pop("p").bad
    with open(o.report, "w") as f:
        json.dump({"clients": stats, "forgotten": forgotten, "refused": refused, "relayed_bytes": relayed}, f)


if __name__ == "__main__":
    main()
