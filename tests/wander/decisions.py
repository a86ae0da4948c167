"""Recorded decisions of the wanderer: the exact commands the core WanderDriver gives on the bundled worlds.

``test_decisions.py`` replays these runs and asserts every command float is what it was when the fixture was
recorded, so that speeding the wanderer up can never change what it decides. Each step also records a digest
of the wanderer's inputs (scan and odometry), so that a failure tells a changed simulation from a changed
wanderer. Re-record (only when a behaviour change is intended, and say so in the commit) with
``.venv/bin/python tests/wander/decisions.py``.
"""

from __future__ import annotations

import sys
import zlib
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
FIXTURE = Path(__file__).with_name("data") / "decisions.npz"
# (world, seed, steps): a minute of rooms and corridor, half a minute of four robots meeting.
RUNS = [("rooms.world", 3, 600), ("corridor.world", 4, 600), ("multi_robots.world", 5, 300)]


def run(world: str, seed: int, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Commands (steps, robots, 3) and input digests (steps, robots) of a run stepped as the ROS sessions step:
    the world first, then every wanderer answers the new scan."""
    from stage_sim.runs.driver import WanderDriver
    from stage_sim.sim.simulation import Simulation
    from stage_sim.worldfile.loader import load_world

    sim = Simulation(load_world(REPO / "worlds" / world), seed=seed)
    driver = WanderDriver(sim, seed)
    robots = sorted(driver.wanderers)
    commands = np.zeros((steps, len(robots), 3))
    digests = np.zeros((steps, len(robots)), dtype=np.uint32)
    for k in range(steps):
        sim.step()
        for j, robot in enumerate(robots):
            scan = np.ascontiguousarray(sim.scans[robot][0].ranges)
            digests[k, j] = zlib.crc32(np.ascontiguousarray(sim.odometry_poses[robot]).tobytes(), zlib.crc32(scan))
        driver.decide()
        for j, robot in enumerate(robots):
            commands[k, j] = driver.wanderers[robot].command
    return commands, digests


def record() -> None:
    arrays = {}
    for world, seed, steps in RUNS:
        arrays[f"{world}:commands"], arrays[f"{world}:digests"] = run(world, seed, steps)
    FIXTURE.parent.mkdir(exist_ok=True)
    np.savez_compressed(FIXTURE, **arrays)
    print(f"recorded {FIXTURE}")


if __name__ == "__main__":
    sys.path.insert(0, str(REPO))
    record()
