"""A simulation whose kernels nobody chose starts on numpy and switches to numba mid-run, unnoticed.

The switch must not change a single pose, odometry value, stall flag, range or intensity: the run that
switched equals a run on numpy from start to end, bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from stage_sim.sim import kernel_upgrade
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text
from tests.sim.test_kernel_identity import crowd_world

STEPS = 30


@pytest.fixture
def numba_not_loaded(monkeypatch):
    """This process as a fresh one sees it: nobody chose kernels and none are loaded yet."""
    monkeypatch.delenv("STAGE_SIM_KERNELS", raising=False)
    monkeypatch.setattr(kernel_upgrade, "_LOADED", {"numba": False})


def frames(sim: Simulation, switch_at: int | None = None) -> tuple[list[tuple], list[str]]:
    """Every step's state under seeded random commands, and the kernels each step ran on."""
    commands = np.random.default_rng(4).uniform([-0.4, -0.4, -1.5], [0.8, 0.4, 1.5], (STEPS, len(sim.robots), 3))
    out, used = [], []
    for step in range(STEPS):
        if step == switch_at:
            sim.wait_for_kernels(timeout=120)
        for i, command in enumerate(commands[step]):
            sim.set_velocity(i, *command)
        used.append(sim.kernels)
        sim.step()
        scans = [(s.ranges.tobytes(), s.intensities.tobytes()) for robot in sim.scans for s in robot]
        out.append((sim.true_poses.tobytes(), sim.odometry_poses.tobytes(), sim.stalled.tobytes(), scans))
    return out, used


@pytest.mark.parametrize("quiet", [False, True])
def test_unchosen_kernels_switch_to_numba_without_changing_the_run(numba_not_loaded, quiet):
    """``quiet``: without noise and low robots, the world numba steps fused once it has switched."""
    text = crowd_world(2).replace("samples 271", "samples 91")
    if quiet:
        text = text.replace(" noise [0.0004 0.01 0.5]", "").replace(" size [0.4 0.3 0.05]", "")
    world = load_world_text(text, "crowd.world")
    switching = Simulation(world, seed=2)
    assert switching.kernels == "numpy"
    switched, used = frames(switching, switch_at=10)
    switch = used.index("numba")
    assert 0 < switch <= 11 and used[switch:] == ["numba"] * (STEPS - switch)
    assert kernel_upgrade.numba_loaded()
    assert (switching._fused is not None) == quiet
    reference, _ = frames(Simulation(world, seed=2, kernels="numpy"))
    assert switched == reference


def test_explicit_choices_and_loaded_kernels_start_at_once(numba_not_loaded, monkeypatch):
    world = load_world_text(crowd_world(0).replace("samples 271", "samples 91"), "crowd.world")
    assert Simulation(world, kernels="numpy").kernels == "numpy"
    monkeypatch.setenv("STAGE_SIM_KERNELS", "numpy")
    assert Simulation(world).kernels == "numpy"
    monkeypatch.delenv("STAGE_SIM_KERNELS")
    assert Simulation(world, kernels="numba").kernels == "numba"
    assert Simulation(world).kernels == "numba"  # this process has loaded them now


def test_a_world_with_many_beams_waits_for_numba(numba_not_loaded):
    world = load_world_text(crowd_world(1), "crowd.world")  # 16 robots x 271 beams
    assert sum(r.sensor.samples for robot in Simulation(world, kernels="numpy").robots for r in robot.rangers) > \
        kernel_upgrade.MAX_NUMPY_BEAMS
    assert Simulation(world).kernels == "numba"
