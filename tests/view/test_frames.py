"""What a frame tells the page about motion: the commanded velocity and the true one, zero while stalled."""

from __future__ import annotations

import json

import pytest

from stage_sim.sim.simulation import Simulation
from stage_sim.view.frames import FrameSampler
from stage_sim.worldfile.loader import load_world_text

AGAINST_A_WALL = """resolution 0.02
model( size [1 4 1] pose [1 0 0 0] )
position( size [0.4 0.4 0.2] pose [0 0 0 0] )
"""


def frame_of(sim: Simulation) -> dict:
    return json.loads(FrameSampler(sim).take(now=0.0, paused=False, speedup=1.0, force=True))


def test_a_moving_robot_moves_as_commanded() -> None:
    sim = Simulation(load_world_text(AGAINST_A_WALL, "wall.world"), seed=0, kernels="numpy")
    sim.set_velocity(0, -0.5, 0.0, 0.2)
    sim.step()
    frame = frame_of(sim)
    assert frame["stalled"] == [False]
    assert frame["velocities"] == [[-0.5, 0.0, 0.2]]
    assert frame["true_velocities"] == [[-0.5, 0.0, 0.2]]


def test_a_stalled_robot_shows_its_command_and_no_motion() -> None:
    sim = Simulation(load_world_text(AGAINST_A_WALL, "wall.world"), seed=0, kernels="numpy")
    for _ in range(10):
        sim.set_velocity(0, 1.0, 0.0, 0.0)
        sim.step()
    frame = frame_of(sim)
    assert frame["stalled"] == [True]
    assert frame["velocities"] == [[1.0, 0.0, 0.0]]
    assert frame["true_velocities"] == [[0.0, 0.0, 0.0]]
    assert sim.true_poses[0][0] == pytest.approx(0.3, abs=0.1)  # it got to the wall and stayed there
