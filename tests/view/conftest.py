"""A core-only simulation served live for the view tests, and one headless Chromium per test module."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from stage_sim.sim.simulation import Simulation
from stage_sim.view import LiveView, PacedLoop, ViewSettings

REPO = Path(__file__).resolve().parents[2]
ROOMS = REPO / "worlds" / "rooms.world"
CHROMIUM = Path("/usr/bin/chromium")
# As root on a machine with no network: no sandbox, no GPU, nothing that phones home (Playwright adds
# --headless and a fresh --user-data-dir of its own).
CHROMIUM_FLAGS = [
    "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
    "--disable-component-update", "--disable-sync",
]


@dataclass
class Served:
    """A simulation stepping on its own thread with its view served on a free port."""

    sim: Simulation
    loop: PacedLoop
    view: LiveView
    url: str
    stop: threading.Event
    thread: threading.Thread

    @property
    def ws_url(self) -> str:
        return self.url.replace("http://", "ws://") + "ws"

    def close(self) -> None:
        self.stop.set()
        self.thread.join(timeout=10)
        self.view.close()


def serve(world: Path = ROOMS, speedup: float = 1.0, readonly: bool = False, port: int = 0,
          controller: bool = False) -> Served:
    """Start serving ``world`` (watchdog 0.2 s, as stageros) at ``speedup``; the caller closes it."""
    sim = Simulation.from_world(world, seed=1, watchdog_timeout=0.2)
    before = None
    if controller:
        from stage_sim.runs.driver import WanderDriver

        before = WanderDriver(sim, 1).decide
    loop = PacedLoop(sim, speedup, before)
    view = LiveView(sim, loop, ViewSettings(port=port, readonly=readonly))
    url = view.start()
    stop = threading.Event()
    thread = threading.Thread(target=loop.run, args=(stop, view), daemon=True)
    thread.start()
    return Served(sim, loop, view, url, stop, thread)


@pytest.fixture
def served() -> Iterator[Served]:
    """rooms.world in real time, served on a free port."""
    running = serve()
    try:
        yield running
    finally:
        running.close()


@pytest.fixture(scope="module")
def browser():
    """Debian's Chromium, headless, through Playwright; one per test module."""
    if not CHROMIUM.exists():
        pytest.skip(f"no Chromium at {CHROMIUM}: install Debian's 'chromium' package (.ci/run does) to run the "
                    "browser tests")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_FLAGS)
        try:
            yield chromium
        finally:
            chromium.close()
