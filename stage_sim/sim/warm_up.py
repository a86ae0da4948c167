"""``python -m stage_sim.sim.warm_up``: compile every simulation kernel once into the disk cache (``make setup``
runs it through :mod:`stage_sim.envs.warm_up`, which adds the RL envs' kernels), so that the first simulation a
user starts does not wait for the compiler."""

from __future__ import annotations

import logging

import numpy as np

from stage_sim.backend import numba_available
from stage_sim.sim.backends import backend_for
from stage_sim.sim.simulation import Simulation, SimulationBatch
from stage_sim.worldfile.loader import load_world_text

# Two touching robots with lasers in a walled box: every kernel (both ray-casting loops, robot cells,
# collision) runs at least once; the motion kernels of every drive run through motion_kernels.warm.
WORLD = """
define laser ranger ( sensor( range [0 2] fov 180 samples 5 ) )
define bot position ( size [0.4 0.3 0.2] localization "odom" laser( ) )
model( size [4 4 0.5] pose [0 0 0 0] boundary 1 )
bot( pose [0 0 0 0] )
bot( pose [0.4 0 0 0] )
"""


def warm() -> None:
    """Run every kernel once on a tiny world (compiling what the cache lacks)."""
    if not numba_available():
        return
    from stage_sim.sim import motion_kernels  # imports numba: only once it is known to load

    motion_kernels.warm(2)
    world = load_world_text(WORLD, "warm_up.world")
    sim = Simulation(world, seed=0, kernels="numba")
    sim.set_velocity(0, 0.5, 0.0, 0.5)
    sim.step()
    for threads in (1, 2):  # worlds in one call, on one thread and shared among threads
        twins = [Simulation(world, seed=k, kernels="numba", threads=threads) for k in range(2)]
        SimulationBatch(2).step(twins, [0, 1])
    collision, sensing = sim.build_parts("numba")
    fused = backend_for("numba").fused(collision, sensing.single_cast(), 1, sim.drives)
    if fused is not None:  # its steps ran above; this also loads the cast into a grown robot layer
        fused.warm(sim.start_poses)
    big_batch = np.zeros((4096, 2))  # large enough for the parallel loop
    backend_for("numba").caster(np.zeros((8, 8), dtype=bool), 0.1, (-0.4, -0.4), threads=2).cast(big_batch, 0.0, 1.0)


if __name__ == "__main__":
    logging.basicConfig(format="%(message)s")
    warm()
