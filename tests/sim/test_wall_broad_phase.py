"""The compiled path sweeps against the walls only the bodies that a wall region lies within reach of.

:meth:`CollisionChecker._near_static` drops movers with no region holding a wall cell within their radius,
their step and two cells; the numpy reference sweeps every mover. Robots driven at a thin wall from many
distances and speeds (some far from it, some reaching it within a step, some fast enough to need
sub-steps) must stall, or not, alike under both.
"""

from __future__ import annotations

import numpy as np

from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text

WORLD = """
resolution 0.002
interval_sim 100
define wall model ( color "black" )
wall( size [0.002 6 1] pose [4 3 0 0] )
wall( size [0.6 0.002 1] pose [1 5.5 0 0] )
define bot position ( size [0.3 0.24 0.2] drive "omni" )
"""


def lined_up() -> str:
    """Robots from 3.5 m to 0.3 m short of the thin wall, facing it, a few near the short wall too."""
    rows = [f"bot( pose [{3.7 - 0.3 * i:.2f} {0.4 + 0.45 * i:.2f} 0 {(-1) ** i * 10}] )" for i in range(12)]
    return WORLD + "\n".join(rows) + "\n"


def run(kernels: str, steps: int = 14) -> tuple[list[bytes], int, int]:
    """Poses and stalls after every step, stalls in all, and how many movers the first step swept."""
    sim = Simulation(load_world_text(lined_up(), "wall.world"), seed=2, kernels=kernels)
    speeds = np.random.default_rng(4).uniform(0.3, 3.0, len(sim.robots))
    frames, stalls, swept = [], 0, -1
    for step in range(steps):
        for i, speed in enumerate(speeds):
            sim.set_velocity(i, speed, 0.2 * (-1) ** (i + step), 0.5)
        before = sim.true_poses
        sim.step()
        if step == 0:  # the movers of the first step that the narrowing keeps (the velocities it was given)
            movers = np.arange(len(sim.robots))
            swept = sim._collision._near_static(before, sim.velocities, sim.interval, movers).size
        frames.append(sim.true_poses.tobytes() + sim.stalled.tobytes())
        stalls += int(sim.stalled.sum())
    return frames, stalls, swept


def test_robots_at_a_wall_stall_alike_with_and_without_the_broad_phase() -> None:
    compiled, stalls, swept = run("numba")
    reference, _, _ = run("numpy")
    assert compiled == reference
    assert stalls > 10  # robots reach the walls and stall there
    assert 0 < swept < 12  # the first step swept the robots near a wall only
