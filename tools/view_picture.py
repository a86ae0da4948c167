"""The README's picture of the browser view: ``python tools/view_picture.py OUT.png`` (``make pictures``).

Runs ``--world`` (default multi_robots.world) with the wanderer for ``--sim-seconds`` at 4x real time, watched
by a page in Debian's headless Chromium; then pauses it, clicks the first robot and saves a screenshot.
"""

from __future__ import annotations

import argparse
import math
import sys
import threading
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from stage_sim.runs.driver import WanderDriver  # noqa: E402 (after the path is set)
from stage_sim.runs.pacing import WATCHDOG_S  # noqa: E402
from stage_sim.sim.simulation import Simulation  # noqa: E402
from stage_sim.view import LiveView, PacedLoop, ViewSettings  # noqa: E402
from tests.view.conftest import CHROMIUM, CHROMIUM_FLAGS  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", type=Path)
    parser.add_argument("--world", default=str(REPO / "worlds" / "multi_robots.world"))
    parser.add_argument("--sim-seconds", type=float, default=20.0)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if not CHROMIUM.exists():
        print(f"view_picture: no Chromium at {CHROMIUM} (apt-get install chromium)", file=sys.stderr)
        return 1
    from playwright.sync_api import sync_playwright

    sim = Simulation.from_world(args.world, seed=args.seed, watchdog_timeout=WATCHDOG_S)
    loop = PacedLoop(sim, 4.0, WanderDriver(sim, args.seed).decide, end=args.sim_seconds)
    view = LiveView(sim, loop, ViewSettings(port=0))
    url = view.start()
    stop = threading.Event()
    runner = threading.Thread(target=loop.run, args=(stop, view))
    runner.start()
    # The page watches the run from its start, so that it draws the trail too; then the world pauses.
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_FLAGS)
        page = browser.new_page(viewport={"width": 1000, "height": 760}, device_scale_factor=1)
        page.goto(url)
        runner.join()
        loop.set_paused(True)
        loop.pacer.end = math.inf  # no more steps while paused; the loop goes on serving the view
        final = threading.Thread(target=loop.run, args=(stop, view))  # serves the paused world's last frame
        final.start()
        page.wait_for_function("t => stageView.state.drawnFrame.paused && stageView.state.drawnFrame.time >= t",
                               arg=sim.sim_time - 1e-6)
        box = page.locator("#world").bounding_box()
        x, y = page.evaluate("([x, y]) => stageView.worldToCanvas(x, y)", [float(v) for v in sim.true_poses[0][:2]])
        page.mouse.click(box["x"] + x, box["y"] + y)  # select the first robot, as a user would
        page.wait_for_function("stageView.state.selected === 0 && !document.getElementById('selection').hidden")
        page.screenshot(path=str(args.output))
        browser.close()
    stop.set()
    final.join()
    view.close()
    print(f"{args.output}: the view of {Path(args.world).name} at sim time {sim.sim_time:g} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
