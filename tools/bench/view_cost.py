#!/usr/bin/env python3
"""view_cost.py -- the pages of view_cost.sh: two that draw beams (the full view and Cockpit's fan tile), acknowledging
as view.js does (at each animation frame, 60 a second, when 8 beams wait or 100 ms passed), and Cockpit's status tile
(text only). Runs for --seconds, then prints the beams and texts each page received as JSON.
  view_cost.py --url ws://127.0.0.1:PORT/ws --seconds S
"""
import argparse
import asyncio
import json

from websockets.asyncio.client import connect


async def page(url, beams, out, seconds):
    got = {"beams": 0, "texts": 0}
    out.append(got)
    loop = asyncio.get_running_loop()
    end = loop.time() + seconds
    async with connect(url, max_size=1 << 20, open_timeout=60) as ws:
        await ws.send(json.dumps({"filtered": False} if beams else {"beams": False}))
        acked, acked_at = 0, loop.time()
        while loop.time() < end:
            try:
                m = await asyncio.wait_for(ws.recv(), timeout=1 / 60)
            except asyncio.TimeoutError:
                m = None
            if isinstance(m, bytes):
                got["beams"] += 1
            elif m is not None:
                got["texts"] += 1
            now = loop.time()
            if beams and got["beams"] != acked and (got["beams"] - acked >= 8 or now - acked_at >= 0.1):
                await ws.send(json.dumps({"received": got["beams"]}))
                acked, acked_at = got["beams"], now


async def main_async(a):
    out = []
    await asyncio.gather(page(a.url, True, out, a.seconds), page(a.url, True, out, a.seconds),
                         page(a.url, False, out, a.seconds))
    print(json.dumps(out))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--url", required=True)
    ap.add_argument("--seconds", type=float, required=True)
    asyncio.run(main_async(ap.parse_args()))


if __name__ == "__main__":
    main()
