"""The compiled sweep looks at a body's points only where a wall region lies within the body's radius.

:func:`~stage_sim.sim.sweep_kernels.near_layer` lets the compiled static test skip a probe pose with no
region holding a wall cell within the robot's radius and two cells; the numpy reference tests every point
of every probe. Robots driven at thin walls from many distances and speeds (some far from them, some
reaching them within a step, some fast enough to need sub-steps) must stall, or not, alike under both.
"""

from __future__ import annotations

import numpy as np

from stage_sim.sim.simulation import Simulation
from stage_sim.sim.sweep_kernels import near_layer
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
    """Robots 0.3 m to 3.6 m short of the thin wall, facing it, the last ones near the short wall too."""
    rows = [f"bot( pose [{3.7 - 0.3 * i:.2f} {0.4 + 0.45 * i:.2f} 0 {(-1) ** i * 10}] )" for i in range(12)]
    return WORLD + "\n".join(rows) + "\n"


def run(kernels: str, steps: int = 14) -> tuple[list[bytes], int, Simulation]:
    """Poses and stalls after every step, and the stalls in all."""
    sim = Simulation(load_world_text(lined_up(), "wall.world"), seed=2, kernels=kernels)
    speeds = np.random.default_rng(4).uniform(0.3, 3.0, len(sim.robots))
    frames, stalls = [], 0
    for step in range(steps):
        for i, speed in enumerate(speeds):
            sim.set_velocity(i, speed, 0.2 * (-1) ** (i + step), 0.5)
        sim.step()
        frames.append(sim.true_poses.tobytes() + sim.stalled.tobytes())
        stalls += int(sim.stalled.sum())
    return frames, stalls, sim


def near_a_wall(sim: Simulation, poses: np.ndarray) -> list[bool]:
    """Whether each robot's probe at ``poses`` would have its points looked at (a wall region in reach)."""
    layer = sim.static.collision_tiles(0.0, 0.2)
    grid, resolution = layer.grid, sim.static.resolution
    ox, oy = sim.static.origin_xy
    return [near_layer(x, y, sim._collision.bodies.radius[i] + 2 * resolution, resolution, ox, oy, grid.slots,
                       grid.place, layer.tile_of_slot) for i, (x, y, _) in enumerate(poses)]


def test_robots_at_a_wall_stall_alike_with_and_without_the_broad_phase() -> None:
    compiled, stalls, sim = run("numba")
    reference, _, _ = run("numpy")
    assert compiled == reference
    assert stalls > 10  # robots reach the walls and stall there
    near = near_a_wall(sim, sim.true_poses)
    assert any(near) and not all(near)  # at the end, the points of some robots are looked at, others' skipped
