"""A simulation never writes an array it has exposed: every change of its poses, odometry, velocities, stall flags
or measured beams replaces the array. A bag recording relies on it: it keeps a reference to each step's arrays,
not a copy, until it sends a batch of steps (stage_sim/bags/step_state.py)."""

from __future__ import annotations

import numpy as np
import pytest

from stage_sim.sim.simulation import Simulation, SimulationBatch
from stage_sim.worldfile.loader import load_world_text
from tests.sim.test_simulation_batch import ring_world

EXPOSED = ("true_poses", "odometry_poses", "velocities", "stalled")


def exposed(sim: Simulation) -> list[tuple[np.ndarray, bytes]]:
    """Each exposed array as the simulation holds it now, with a copy of its bytes."""
    beams = sim.measured_beams
    arrays = [getattr(sim, name) for name in EXPOSED]
    if beams is not None:
        arrays += [beams.ranges, beams.intensities]
    return [(array, array.tobytes()) for array in arrays]


def disturb(step: int, sim: Simulation) -> None:
    """Between steps, what users do: drive every robot (robot 0 into the others, so that it stalls), move a
    stalled robot, reset the poses."""
    n = len(sim.robots)
    sim.set_velocities(np.arange(n), np.tile([0.6, 0.0, 0.4 if step % 7 else -0.9], (n, 1)))
    if step % 5 == 3:
        stalled = np.flatnonzero(sim.stalled)
        robot = int(stalled[0]) if stalled.size else step % n
        sim.set_pose(robot, 8.0 + 0.1 * (step % 9), 8.0, 0.3)
    if step % 17 == 16:
        sim.reset_positions()


def assert_unchanged(kept: list[tuple[np.ndarray, bytes]]) -> None:
    """No array kept with its bytes has changed since."""
    changed = [k for k, (array, data) in enumerate(kept) if array.tobytes() != data]
    assert not changed, f"{len(changed)} arrays exposed by earlier steps were written later"


@pytest.mark.parametrize("kernels", ["numpy", "numba"])
def test_a_simulation_replaces_the_arrays_it_exposed_instead_of_writing_them(kernels: str) -> None:
    sim = Simulation(load_world_text(ring_world(6, 0.6), "ring.world"), seed=3, kernels=kernels)
    kept, stalls = [], 0
    for step in range(60):
        disturb(step, sim)
        sim.step()
        stalls += int(sim.stalled.any())
        kept += exposed(sim)
    assert stalls > 5  # set_pose cleared stall flags of robots that had them
    assert_unchanged(kept)


def test_simulations_stepped_in_a_batch_replace_the_arrays_they_exposed_too() -> None:
    """The batch copies a world's new state (after a pose set or a reset) into its stacked arrays: new ones, as
    the last step's rows are the arrays the synced simulations exposed."""
    sims = [Simulation(load_world_text(ring_world(6, 0.6), f"ring{k}.world"), seed=k, kernels="numba")
            for k in range(3)]
    batch = SimulationBatch(len(sims))
    kept = []
    for step in range(90):
        if step % 3 == 0:  # changed and read every third step, left behind in the batch between
            batch.sync()  # up to date before they are changed
            for sim in sims:
                disturb(step // 3 + sims.index(sim), sim)
        batch.step(sims, range(len(sims)))
        assert batch.whole
        if step % 3 == 2:
            batch.sync()
            for sim in sims:
                kept += exposed(sim)
    assert_unchanged(kept)
