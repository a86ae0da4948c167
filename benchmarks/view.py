"""What the browser view costs ``stageros``: CPU at real time, sim rate at full speed, memory under page churn.

Run with the venv's python: ``.venv/bin/python benchmarks/view.py [--seconds S] [--churn-seconds S]``. Prints
one JSON object per line:

* ``cpu``: stageros on rooms.world in real time, ``-g`` against one Chromium page open; ``cpu_share`` is
  process CPU seconds per wall second (1.0 = one core), ``added_share`` the difference (target < 0.05).
* ``rate``: ``--speedup 0``, no view against three pages (WebSocket clients in another process that read
  every frame, as a page does; Chromium's drawing would only compete for this machine's two cores);
  ``realtime_factor`` from /clock, ``ratio`` = with pages / without (target >= 0.9).
* ``churn``: stageros' RSS before and after ``--churn-seconds`` of a Chromium page opening, loading and
  closing every second (target: growth < 20 MB over 600 s).

stageros is pinned to core 0 (``taskset -c 0``), this process and Chromium to core 1, so the clients do not
take the simulator's CPU; the figures are still noisy on a shared machine.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import re
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import aiohttp
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rosgraph_msgs.msg import Clock

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
sys.path.insert(0, str(REPO))
STAGEROS = Path(sys.executable).with_name("stageros")
ROOMS = REPO / "worlds" / "rooms.world"

from stageros import cpu_seconds  # noqa: E402 - a process's CPU seconds from /proc, shared with stageros.py

from tests.view.conftest import CHROMIUM, CHROMIUM_FLAGS  # noqa: E402 (after the path is set)


def rss_mb(pid: int) -> float:
    match = re.search(r"VmRSS:\s+(\d+)", Path(f"/proc/{pid}/status").read_text())
    return int(match.group(1)) / 1024


@contextmanager
def stageros(*args: str):
    """stageros on core 0; yields (process, view URL or None)."""
    process = subprocess.Popen(["taskset", "-c", "0", str(STAGEROS), *args, str(ROOMS)], env=dict(os.environ),
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    url = None
    try:
        if "-g" not in args:
            for line in process.stdout:
                if line.startswith("view: "):
                    url = line.split()[1]
                    break
        threading.Thread(target=process.stdout.read, daemon=True).start()  # keep the pipe drained
        yield process, url
    finally:
        process.terminate()
        process.wait(timeout=20)


class ClockWatch:
    """The latest /clock value, received on a thread of this process."""

    def __init__(self) -> None:
        rclpy.init()
        self.node = rclpy.create_node("view_benchmark")
        self.latest: float | None = None
        self.node.create_subscription(Clock, "/clock", self._on_clock, 1000)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _on_clock(self, message: Clock) -> None:
        self.latest = message.clock.sec + message.clock.nanosec * 1e-9

    def _spin(self) -> None:
        while not self._stop.is_set():
            self.executor.spin_once(timeout_sec=0.05)

    def wait_for_clock(self, timeout_s: float = 60.0) -> None:
        deadline = time.monotonic() + timeout_s
        while self.latest is None and time.monotonic() < deadline:
            time.sleep(0.05)

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        self.node.destroy_node()
        rclpy.shutdown()


def measure(process: subprocess.Popen, clock: ClockWatch, seconds: float) -> dict:
    clock.wait_for_clock()
    time.sleep(2.0)  # start-up over
    sim0, cpu0, wall0 = clock.latest, cpu_seconds(process.pid), time.monotonic()
    time.sleep(seconds)
    sim1, cpu1, wall1 = clock.latest, cpu_seconds(process.pid), time.monotonic()
    wall = wall1 - wall0
    return {"wall_s": round(wall, 2), "realtime_factor": round((sim1 - sim0) / wall, 3),
            "cpu_share": round((cpu1 - cpu0) / wall, 4)}


def chromium():
    from playwright.sync_api import sync_playwright

    playwright = sync_playwright().start()
    browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_FLAGS)
    return playwright, browser


def open_page(browser, url: str):
    page = browser.new_page(viewport={"width": 1000, "height": 760})
    page.goto(url)
    page.wait_for_function("window.stageView && stageView.state.drawnFrame !== null", timeout=30_000)
    return page


def cpu_case(clock: ClockWatch, seconds: float) -> dict:
    with stageros("-g", "--speedup", "1") as (process, _):
        without = measure(process, clock, seconds)
    playwright, browser = chromium()
    try:
        with stageros("--speedup", "1", "--view-port", "0") as (process, url):
            page = open_page(browser, url)
            with_page = measure(process, clock, seconds)
            frames = page.evaluate("stageView.state.framesReceived")
    finally:
        browser.close()
        playwright.stop()
    return {"case": "cpu", "world": "rooms.world", "speedup": 1, "without_view": without, "one_page": with_page,
            "frames_received": frames,
            "added_share": round(with_page["cpu_share"] - without["cpu_share"], 4)}


def _watch_frames(url: str, pages: int, stop: threading.Event, counts: list[int]) -> None:
    """``pages`` WebSocket clients reading every frame until ``stop``."""

    async def one(index: int) -> None:
        async with aiohttp.ClientSession() as session, session.ws_connect(url) as ws:
            while not stop.is_set():
                try:
                    await ws.receive(timeout=0.5)
                except asyncio.TimeoutError:
                    continue
                counts[index] += 1

    async def every() -> None:
        await asyncio.gather(*(one(i) for i in range(pages)))

    asyncio.run(every())


def rate_case(clock: ClockWatch, seconds: float, pages: int = 3) -> dict:
    with stageros("-g", "--speedup", "0") as (process, _):
        without = measure(process, clock, seconds)
    with stageros("--speedup", "0", "--view-port", "0") as (process, url):
        stop, counts = threading.Event(), [0] * pages
        ws_url = url.replace("http://", "ws://") + "ws"
        watcher = threading.Thread(target=_watch_frames, args=(ws_url, pages, stop, counts), daemon=True)
        watcher.start()
        try:
            with_pages = measure(process, clock, seconds)
        finally:
            stop.set()
            watcher.join(timeout=10)
    return {"case": "rate", "world": "rooms.world", "speedup": 0, "without_view": without,
            f"{pages}_pages": with_pages, "frames_per_page_per_s": round(min(counts) / (seconds + 2.0), 1),
            "ratio": round(with_pages["realtime_factor"] / without["realtime_factor"], 3)}


def churn_case(seconds: float) -> dict:
    playwright, browser = chromium()
    try:
        with stageros("--speedup", "1", "--view-port", "0") as (process, url):
            open_page(browser, url).close()  # warm-up: the first page builds every cache
            time.sleep(2.0)
            before = rss_mb(process.pid)
            start, pages = time.monotonic(), 0
            while time.monotonic() - start < seconds:
                due = start + pages + 1
                page = open_page(browser, url)
                page.close()
                pages += 1
                time.sleep(max(0.0, due - time.monotonic()))
            time.sleep(2.0)
            after = rss_mb(process.pid)
    finally:
        browser.close()
        playwright.stop()
    return {"case": "churn", "world": "rooms.world", "seconds": round(time.monotonic() - start, 1), "pages": pages,
            "rss_before_mb": round(before, 1), "rss_after_mb": round(after, 1),
            "growth_mb": round(after - before, 1)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=30.0, help="wall seconds measured per run (default 30)")
    parser.add_argument("--churn-seconds", type=float, default=600.0,
                        help="wall seconds of pages connecting and disconnecting (default 600)")
    parser.add_argument("--cases", default="cpu,rate,churn", help="comma-separated subset of cpu,rate,churn")
    args = parser.parse_args()
    os.sched_setaffinity(0, {1} if os.cpu_count() and os.cpu_count() > 1 else {0})
    cases = args.cases.split(",")
    clock = ClockWatch() if {"cpu", "rate"} & set(cases) else None
    try:
        if "cpu" in cases:
            print(json.dumps(cpu_case(clock, args.seconds)), flush=True)
        if "rate" in cases:
            print(json.dumps(rate_case(clock, args.seconds)), flush=True)
    finally:
        if clock is not None:
            clock.close()
    if "churn" in cases:
        print(json.dumps(churn_case(args.churn_seconds)), flush=True)


if __name__ == "__main__":
    main()
