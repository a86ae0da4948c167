"""stageros' browser view: served by default (``-g``: none), and a page's controls take the node's own paths."""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import aiohttp
import pytest
from rosgraph_msgs.msg import Clock

from stage_sim.ros.stageros import StageRos
from stage_sim.ros.view import viewing

STAGEROS = Path(sys.executable).with_name("stageros")


def view_args(no_view: bool = False) -> argparse.Namespace:
    return argparse.Namespace(no_view=no_view, view_host="127.0.0.1", view_port=0, view_readonly=False)


@pytest.fixture
def viewed(ros_context, executor) -> Iterator[tuple[StageRos, str, list[float]]]:
    """stageros on rooms.world in real time with its view, spun on a thread; yields (node, ws URL, /clock)."""
    stage = StageRos("rooms.world", context=ros_context)
    executor.add_node(stage)
    clock: list[float] = []
    stage.create_subscription(Clock, "/clock", lambda m: clock.append(m.clock.sec + m.clock.nanosec * 1e-9), 100)
    stop = threading.Event()
    with viewing(stage, view_args()) as view:
        assert view is not None

        def spin() -> None:
            while not stop.is_set():
                executor.spin_once(timeout_sec=0.05)

        spinner = threading.Thread(target=spin)
        spinner.start()
        try:
            yield stage, view.server.url.replace("http://", "ws://") + "ws", clock
        finally:
            stop.set()
            spinner.join(timeout=10)


async def _send(url: str, *messages: dict, wait_s: float = 0.3) -> None:
    async with aiohttp.ClientSession() as session, session.ws_connect(url) as ws:
        await ws.receive(timeout=5)  # the scene
        for message in messages:
            await ws.send_str(json.dumps(message))
        await asyncio.sleep(wait_s)


def test_pause_stops_the_clock_and_speed_changes_the_pace(viewed) -> None:
    stage, url, clock = viewed
    asyncio.run(_send(url, {"type": "pause", "paused": True}))
    paused_at, ticks = stage.sim.sim_time, len(clock)
    time.sleep(0.8)
    assert stage.sim.sim_time == paused_at
    assert len(clock) == ticks  # no /clock while paused

    asyncio.run(_send(url, {"type": "speed", "speedup": 4.0}, {"type": "pause", "paused": False}, wait_s=0.1))
    sim0, wall0 = stage.sim.sim_time, time.monotonic()
    time.sleep(2.0)
    rate = (stage.sim.sim_time - sim0) / (time.monotonic() - wall0)
    assert stage.pacer.speedup == 4.0
    assert rate == pytest.approx(4.0, rel=0.2)


def test_keys_drive_through_cmd_vel_checks_and_the_watchdog_and_reset_goes_home(viewed) -> None:
    stage, url, _ = viewed
    start = tuple(stage.sim.true_poses[0])
    drive = {"type": "drive", "robot": "robot", "vx": 0.0, "vy": 0.0, "va": 1.0}
    asyncio.run(_send(url, drive, wait_s=0.05))
    assert stage.sim.commands[0][2] == 1.0
    time.sleep(0.6)  # well past the 0.2 s watchdog in real time
    assert tuple(stage.sim.commands[0]) == (0.0, 0.0, 0.0)
    assert stage.sim.true_poses[0][2] != pytest.approx(start[2])  # it did turn meanwhile

    asyncio.run(_send(url, {"type": "pose", "robot": "robot", "x": 5.0, "y": 5.0}))
    assert tuple(stage.sim.true_poses[0][:2]) == pytest.approx((5.0, 5.0))
    asyncio.run(_send(url, {"type": "reset"}))
    assert tuple(stage.sim.true_poses[0]) == pytest.approx(start)


def test_no_view_with_g(ros_context) -> None:
    stage = StageRos("rooms.world", context=ros_context, autostep=False)
    try:
        with viewing(stage, view_args(no_view=True)) as view:
            assert view is None
    finally:
        stage.destroy_node()


@pytest.mark.slow
def test_the_console_script_prints_the_view_url_once_and_minus_g_none(tmp_path) -> None:
    def output_of(*args: str, until: str) -> list[str]:
        """stageros' output lines until one holds ``until``, and a second more."""
        process = subprocess.Popen([str(STAGEROS), *args, "rooms.world"], cwd=tmp_path, env=dict(os.environ),
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        lines = []
        try:
            for line in process.stdout:
                lines.append(line.rstrip("\n"))
                if until in line:
                    break
            time.sleep(1.0)
        finally:
            process.terminate()
            lines += process.communicate(timeout=30)[0].splitlines()
        return lines

    views = [line for line in output_of("--view-port", "0", until="view: ") if line.startswith("view: ")]
    assert len(views) == 1 and views[0].startswith("view: http://127.0.0.1:") and views[0].endswith("/")
    assert not [line for line in output_of("-g", until="robot(s), interval_sim") if line.startswith("view: ")]
