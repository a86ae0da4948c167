"""Long moves, checked at several intermediate poses against the walls, are identical under both kernels.

With ``interval_sim`` 500 ms a robot at 1 m/s moves 0.5 m per step, more than half its 0.3 m width, so the
static test runs at three or four sub-steps: the compiled sweep (sim/sweep_kernels.py) must refuse exactly
the moves the numpy reference refuses, and leave every pose the same bit for bit.
"""

from __future__ import annotations

import numpy as np

from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text

WORLD = """
resolution 0.02
interval_sim 500
define wall model ( color "black" )
wall( size [6 0.04 1] pose [3 0 0 0] )
wall( size [6 0.04 1] pose [3 4 0 0] )
wall( size [0.04 4 1] pose [0 2 0 0] )
wall( size [0.04 4 1] pose [6 2 0 0] )
wall( size [0.04 1.5 1] pose [3 2 0 0] )
wall( name "low" size [1 0.3 0.05] pose [1.5 3 0 30] )
define bot position ( size [0.4 0.3 0.2] drive "omni" localization "odom" )
"""


def run(kernels: str, seed: int) -> tuple[list[bytes], int]:
    rng = np.random.default_rng(seed)
    rows = [f"bot( pose [{rng.uniform(0.5, 5.5):.2f} {rng.uniform(0.5, 3.5):.2f} 0 {rng.uniform(-180, 180):.0f}] )"
            for _ in range(12)]
    rows.append('bot( pose [1.5 2.5 0 0] size [0.4 0.3 0.02] )')  # below the low wall: passes over it
    sim = Simulation(load_world_text(WORLD + "\n".join(rows) + "\n", "sweep.world"), seed=seed, kernels=kernels)
    commands = rng.uniform([-1.0, -1.0, -1.5], [1.0, 1.0, 1.5], (40, len(sim.robots), 3))
    frames, stalls = [], 0
    for step in commands:
        for i, command in enumerate(step):
            sim.set_velocity(i, *command)
        sim.step()
        stalls += int(sim.stalled.sum())
        frames.append(sim.true_poses.tobytes() + sim.odometry_poses.tobytes() + sim.stalled.tobytes())
    return frames, stalls


def test_sub_stepped_moves_against_walls_are_identical_under_both_kernels():
    for seed in (0, 1, 2):
        compiled, stalls = run("numba", seed)
        assert compiled == run("numpy", seed)[0]
        assert stalls > 0  # walls refused some of the long moves
