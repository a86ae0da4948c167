"""The view's server through raw HTTP and WebSocket clients: scene, frames, origin rules, ports, and garbage."""

from __future__ import annotations

import asyncio
import json
import logging
import math
import socket
import subprocess
import sys
import time

import aiohttp
import pytest

from stage_sim.view.frames import MAX_FPS
from tests.view.conftest import REPO, serve


async def _receive_json(ws: aiohttp.ClientWebSocketResponse, timeout: float = 5.0) -> dict:
    message = await ws.receive(timeout=timeout)
    assert message.type == aiohttp.WSMsgType.TEXT, message
    return json.loads(message.data)


def test_a_page_gets_the_scene_then_frames_at_most_30_a_second(served) -> None:
    async def watch() -> tuple[dict, list[dict], float]:
        async with aiohttp.ClientSession() as session, session.ws_connect(served.ws_url) as ws:
            scene = await _receive_json(ws)
            frames = [await _receive_json(ws)]
            start = time.monotonic()
            while time.monotonic() - start < 1.5:
                frames.append(await _receive_json(ws))
            return scene, frames, time.monotonic() - start

    served.loop.set_speedup(0)  # thousands of steps a second: frames must still come at most 30 a second
    scene, frames, seconds = asyncio.run(watch())
    assert scene["type"] == "scene" and scene["world"] == "rooms.world"
    assert [robot["name"] for robot in scene["robots"]] == ["robot"]
    assert scene["robots"][0]["rangers"][0]["samples"] == 240
    assert all(frame["type"] == "frame" for frame in frames)
    assert len(frames) - 1 <= MAX_FPS * seconds + 2
    assert len(frames) >= 10
    assert frames[-1]["time"] > frames[0]["time"] + 1.0  # the simulation ran far faster than the frames
    pose = frames[-1]["poses"][0]
    assert len(pose) == 3 and all(math.isfinite(v) for v in pose)


def test_the_page_and_its_map_are_served(served) -> None:
    async def fetch() -> list[tuple[int, str, bytes]]:
        async with aiohttp.ClientSession() as session:
            results = []
            for path in ("", "map.png", "static/js/main.js", "static/view.css", "static/../server.py"):
                async with session.get(served.url + path) as response:
                    results.append((response.status, response.content_type, await response.read()))
            return results

    page, image, script, style, escape = asyncio.run(fetch())
    assert page[0] == 200 and b"<canvas" in page[2]
    assert image[:2] == (200, "image/png") and image[2].startswith(b"\x89PNG")
    assert script[0] == 200 and b"stageView" in script[2]
    assert style[0] == 200
    assert escape[0] == 404


def test_a_foreign_origin_or_host_is_refused(served) -> None:
    async def attempts() -> tuple[int, int, bool]:
        async with aiohttp.ClientSession() as session:
            with pytest.raises(aiohttp.WSServerHandshakeError) as refused:
                await session.ws_connect(served.ws_url, origin="http://evil.example")
            async with session.get(served.url, headers={"Host": "evil.example"}) as response:
                host_status = response.status
            own = served.url.rstrip("/")
            async with session.ws_connect(served.ws_url, origin=own) as ws:
                accepted = (await _receive_json(ws))["type"] == "scene"
            return refused.value.status, host_status, accepted

    origin_status, host_status, accepted = asyncio.run(attempts())
    assert origin_status == 403
    assert host_status == 403
    assert accepted


def test_a_taken_port_moves_the_view_to_the_next_free_one() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        running = serve(port=port)
        try:
            assert running.view.server.port > port
            assert running.url == f"http://127.0.0.1:{running.view.server.port}/"
        finally:
            running.close()


def test_fuzzed_input_never_slows_the_simulation_and_valid_commands_all_arrive(caplog) -> None:
    """Random bytes, huge frames, NaN, unknown robots, wrong types and a 1,000 messages/s flood, sent by
    another process (as a browser would be), while the simulation steps 50 times a second."""
    running = serve(speedup=5.0)
    try:
        with caplog.at_level(logging.WARNING, logger="stage_sim.view.server"):
            wall0, sim0 = time.monotonic(), running.sim.sim_time
            result = subprocess.run([sys.executable, "-m", "tests.view.fuzz_client", running.ws_url], cwd=REPO,
                                    capture_output=True, text=True, timeout=60)
            wall1, sim1 = time.monotonic(), running.sim.sim_time
            time.sleep(0.2)
        assert result.returncode == 0, result.stderr
        report = json.loads(result.stdout)
        rate = (sim1 - sim0) / (wall1 - wall0)
        assert rate == pytest.approx(5.0, rel=0.1)  # still stepping at its pace
        assert report["garbage_close"] == 1008  # a connection that keeps sending garbage is closed
        assert report["huge_close"] == 1009  # a message over the size limit closes its connection...
        assert report["huger_close"] in (1009, None)  # ...even before the sender has sent it all
        assert report["garbage_sent"] > 20
        assert report["flood_sent"] >= 2900
        server = running.view.server
        assert server.accepted == report["flood_sent"]  # every valid command was taken...
        assert running.view.applied == report["flood_sent"]  # ...and applied, between steps
        assert server.rejected >= 21
        warnings = [r for r in caplog.records if "dropped a page message" in r.getMessage()]
        assert 1 <= len(warnings) <= 3  # rate-limited: one per 5 s
        assert running.thread.is_alive()

        async def still_served() -> dict:
            async with aiohttp.ClientSession() as session, session.ws_connect(running.ws_url) as ws:
                await _receive_json(ws)
                return await _receive_json(ws)

        assert asyncio.run(still_served())["type"] == "frame"
    finally:
        running.close()


def test_a_read_only_view_shows_but_ignores_commands() -> None:
    running = serve(readonly=True)
    try:
        async def try_to_pause() -> dict:
            async with aiohttp.ClientSession() as session, session.ws_connect(running.ws_url) as ws:
                scene = await _receive_json(ws)
                await ws.send_str(json.dumps({"type": "pause", "paused": True}))
                await ws.send_str(json.dumps({"type": "pose", "robot": "robot", "x": 5.0, "y": 5.0, "yaw": 0.0}))
                await asyncio.sleep(0.5)
                return scene

        assert asyncio.run(try_to_pause())["readonly"] is True
        time.sleep(0.2)
        assert not running.loop.pacer.paused
        assert running.view.applied == 0
        assert tuple(running.sim.true_poses[0][:2]) == pytest.approx((11.1, 9.2))
    finally:
        running.close()


def test_viewers_come_and_go_without_stopping_the_simulation(served) -> None:
    async def churn() -> None:
        async with aiohttp.ClientSession() as session:
            for _ in range(20):
                async with session.ws_connect(served.ws_url) as ws:
                    await _receive_json(ws)
            idle = await session.ws_connect(served.ws_url)  # connected, never reads
            await asyncio.sleep(1.0)
            await idle.close()

    sim0, wall0 = served.sim.sim_time, time.monotonic()
    asyncio.run(churn())
    rate = (served.sim.sim_time - sim0) / (time.monotonic() - wall0)
    assert rate == pytest.approx(1.0, rel=0.15)
    time.sleep(0.2)
    assert served.view.server.viewers == 0
