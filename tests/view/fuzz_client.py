"""A hostile page in its own process: ``python -m tests.view.fuzz_client WS_URL`` prints a JSON report.

At once: one connection sends garbage (random bytes, NaN, unknown robots, wrong types, deep nesting) until
the server closes it; two send one oversized message each (100 kB and 50 MB); one floods 1,000 valid
commands a second for 3 s.
"""

from __future__ import annotations

import asyncio
import json
import random
import sys
import time

import aiohttp

GARBAGE = [
    '{"type": "drive", "robot": "robot", "vx": NaN, "vy": 0, "va": 0}',
    '{"type": "drive", "robot": "nobody", "vx": 0.1, "vy": 0, "va": 0}',
    '{"type": "drive", "robot": "robot", "vx": "fast", "vy": 0, "va": 0}',
    '{"type": "drive", "robot": "robot", "vx": true, "vy": 0, "va": 0}',
    '{"type": "pose", "robot": "robot", "x": 1e300, "y": 0, "yaw": 0}',
    '{"type": "pose", "robot": ["robot"], "x": 1, "y": 1, "yaw": 0}',
    '{"type": "speed", "speedup": Infinity}',
    '{"type": "pause", "paused": 1}',
    '{"type": "launch_missiles"}',
    "[" * 3000,
    "[1, 2, 3]",
    "not json at all",
    "",
]
CLOSED = (aiohttp.WSMsgType.CLOSE, aiohttp.WSMsgType.CLOSING, aiohttp.WSMsgType.CLOSED)


async def garbage(url: str, rng: random.Random) -> tuple[int, int | None]:
    """Garbage until the server closes the connection: (messages sent, close code)."""
    async with aiohttp.ClientSession() as session, session.ws_connect(url) as ws:
        sent = 0
        while not ws.closed and sent < 10_000:
            if rng.random() < 0.3:
                await ws.send_bytes(rng.randbytes(rng.randint(1, 2000)))
            else:
                await ws.send_str(rng.choice(GARBAGE))
            sent += 1
            try:
                message = await ws.receive(timeout=0.002)
            except asyncio.TimeoutError:
                continue
            if message.type in CLOSED:
                break
        return sent, ws.close_code


async def huge(url: str, size: int) -> int | None:
    """One message of ``size`` bytes: the close code (None when the server cut the connection mid-send)."""
    async with aiohttp.ClientSession() as session, session.ws_connect(url) as ws:
        try:
            await ws.send_str("x" * size)
        except ConnectionError:
            return None
        while (await ws.receive(timeout=10)).type not in CLOSED:
            pass
        return ws.close_code


async def flood(url: str, seconds: float = 3.0, rate: float = 1000.0) -> int:
    """Valid drive commands at ``rate`` a second: how many were sent."""
    async with aiohttp.ClientSession() as session, session.ws_connect(url) as ws:
        sent = 0
        start = time.monotonic()
        while time.monotonic() - start < seconds:
            delay = start + sent / rate - time.monotonic()
            if delay > 0:
                await asyncio.sleep(delay)
            await ws.send_str(json.dumps({"type": "drive", "robot": "robot", "vx": 0.2, "vy": 0.0, "va": 0.1}))
            sent += 1
        await asyncio.sleep(0.5)
        return sent


async def main(url: str) -> dict:
    rng = random.Random(7)
    (garbage_sent, garbage_close), huge_close, huger_close, flood_sent = await asyncio.gather(
        garbage(url, rng), huge(url, 100_000), huge(url, 50_000_000), flood(url))
    return {"garbage_sent": garbage_sent, "garbage_close": garbage_close, "huge_close": huge_close,
            "huger_close": huger_close, "flood_sent": flood_sent}


if __name__ == "__main__":
    print(json.dumps(asyncio.run(main(sys.argv[1]))))
