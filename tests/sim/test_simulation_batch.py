"""Simulations stepped together (``SimulationBatch``, one compiled call for all worlds) are stepped exactly as
each one's own ``Simulation.step`` steps it: poses, odometry, stall flags, scans, bit for bit, whatever happens
between steps (a pose set, a reset, worlds left out of a step, worlds that cannot join the call)."""

from __future__ import annotations

import numpy as np
import pytest

from stage_sim.sim import fused_kernels
from stage_sim.sim.simulation import Simulation, SimulationBatch
from stage_sim.worldfile.loader import load_world_text
from tests.sim.test_kernel_identity import SPREAD

# The walled 16 m arena of the identity tests, with a block, noisy lasers and odometry errors.
ARENA = (SPREAD.replace("samples 61 )", "samples 61 noise [0.0004 0.01 0.5] )")
         .replace('localization "odom"', 'localization "odom" odom_error [0.05 0.05 0 0.1]')
         + "wall( size [1 2 1] pose [11 5 0 30] )\n")


def ring_world(robots: int, radius: float, laser_interval: int | None = None) -> str:
    """``robots`` robots on a ring around the arena's middle, facing out (they leave a huddle: the robot layer
    grows), with the lasers' update interval in ms when given."""
    rows = [f"bot( pose [{8 + radius * np.cos(a):.3f} {8 + radius * np.sin(a):.3f} 0 {np.degrees(a):.1f}] )"
            for a in np.linspace(0, 2 * np.pi, robots, endpoint=False)]
    text = ARENA + "\n".join(rows) + "\n"
    if laser_interval is not None:
        text = text.replace("laser( pose [0.1 0 -0.1 0] )",
                            f"laser( pose [0.1 0 -0.1 0] update_interval {laser_interval} )")
    return text


def frame(sim: Simulation) -> tuple:
    scans = [(s.ranges.tobytes(), s.intensities.tobytes(), s.stamp) for robot in sim.scans for s in robot]
    return (sim.sim_time_us, sim.true_poses.tobytes(), sim.odometry_poses.tobytes(), sim.stalled.tobytes(),
            sim.velocities.tobytes(), scans)


def lockstep(texts: list[str], kernels: list[str], steps: int, between=None, threads: int = 1, every: int = 1,
             ) -> tuple[list, list, list[bool]]:
    """The same worlds stepped one by one and through a batch under the same random commands, new ones every
    ``every`` steps (the batched simulations synced first, and left behind in the batch between); ``between(step,
    sims)`` changes both sets alike between steps and returns the slots to step (None: all). Returns both runs'
    frames at those steps and, per step, whether every world stepped joined the batch's compiled call (the
    batched simulations on ``threads`` threads)."""
    worlds = [load_world_text(text, f"w{k}.world") for k, text in enumerate(texts)]
    alone = [Simulation(w, seed=k, kernels=kinds) for k, (w, kinds) in enumerate(zip(worlds, kernels, strict=True))]
    batched = [Simulation(w, seed=k, kernels=kinds, threads=threads)
               for k, (w, kinds) in enumerate(zip(worlds, kernels, strict=True))]
    batch = SimulationBatch(len(texts))
    rng = np.random.default_rng(7)
    frames_alone, frames_batched, whole = [], [], []
    slots = list(range(len(texts)))
    for step in range(steps):
        if step % every == 0:
            batch.sync()  # up to date before they are read or changed
            frames_alone.append([frame(sim) for sim in alone])
            frames_batched.append([frame(sim) for sim in batched])
            if between is not None:
                between(step, alone)
                chosen = between(step, batched)
                slots = list(range(len(texts))) if chosen is None else chosen
            for slot in range(len(texts)):
                commands = rng.uniform([-0.2, -0.2, -1.0], [0.9, 0.2, 1.0], (len(alone[slot].robots), 3))
                for sim in (alone[slot], batched[slot]):
                    sim.set_velocities(np.arange(len(sim.robots)), commands)
        for slot in slots:
            alone[slot].step()
        batch.step([batched[slot] for slot in slots], slots)
        whole.append(batch.whole)
    batch.sync()
    frames_alone.append([frame(sim) for sim in alone])
    frames_batched.append([frame(sim) for sim in batched])
    return frames_alone, frames_batched, whole


@pytest.mark.parametrize(("threads", "every"), [(1, 1), (2, 1), (1, 6)])
def test_worlds_stepped_in_one_call_are_stepped_as_each_alone(monkeypatch, threads, every):
    """Four worlds of ten robots (noise, odometry errors, robots leaving a huddle so that the robot layers grow
    inside the batched call), each steps as it steps alone, on one thread or with the worlds shared among two,
    read and commanded at every step or left in the batch for several; every step joins the one compiled call."""
    calls, regrown = [], []
    name = "whole_steps" if threads == 1 else "whole_steps_parallel"
    whole_steps, sense_again = getattr(fused_kernels, name), fused_kernels.sense_again
    monkeypatch.setattr(fused_kernels, name, lambda *args: calls.append(1) or whole_steps(*args))
    monkeypatch.setattr(fused_kernels, "sense_again", lambda *args: regrown.append(1) or sense_again(*args))
    texts = [ring_world(10, radius) for radius in (0.8, 1.0, 1.2, 1.5)]
    alone, batched, whole = lockstep(texts, ["numba"] * 4, 60, threads=threads, every=every)
    assert batched == alone
    assert len(calls) == 60 and all(whole)
    assert regrown


@pytest.mark.parametrize("every", [1, 5])
def test_what_happens_between_steps_is_seen_by_the_next_batched_step(every):
    """A pose set, a reset and worlds left out of some steps (behind in the batch, read only later, with
    ``every`` 5): the batch takes each world's state as it is."""

    def between(step: int, sims: list[Simulation]) -> list[int] | None:
        if step == 10:
            sims[1].set_pose(3, 4.0, 4.0, 1.0)
        if step == 20:
            sims[2].reset(seed=99)
        if step == 30:
            sims[0].reset_positions()
        return [0, 2] if 15 <= step < 25 else None

    alone, batched, whole = lockstep([ring_world(6, 1.5)] * 3, ["numba"] * 3, 40, between, every=every)
    assert batched == alone
    assert all(whole)


@pytest.mark.parametrize("case", ["numpy kernels", "lasers not due every step", "another number of robots"])
def test_worlds_that_cannot_join_the_call_step_on_their_own(case):
    """A world on the numpy kernels, one whose lasers are due every other step only, one with other robots:
    each steps on its own, the others still together, all as they step alone."""
    texts, kernels = [ring_world(6, 1.5)] * 3, ["numba"] * 3
    if case == "numpy kernels":
        kernels[1] = "numpy"
    elif case == "lasers not due every step":
        texts = [texts[0], ring_world(6, 1.5, laser_interval=200), texts[2]]
    else:
        texts = [texts[0], ring_world(4, 1.5), texts[2]]
    alone, batched, whole = lockstep(texts, kernels, 12)
    assert batched == alone
    assert not all(whole)
