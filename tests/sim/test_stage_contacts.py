"""Contacts as Stage 4.3 resolves them (``World::Update``, ``ModelPosition::Move``, ``Block::TestCollision``).

Robots move one by one in index order, each tested at its end pose only, against the raster layer of
``updates % 2``: robots that have not moved yet in this update stand where that layer last saw them (two
updates ago for a robot that moves every update). A refused move keeps the old pose and stalls; a robot
commanded to stand still keeps its stall flag.
"""

from __future__ import annotations

import numpy as np
import pytest

from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text

HEAD = """
resolution 0.02
interval_sim 100
define box position ( size [0.2 0.2 0.2] drive "omni" )
define wall model ( obstacle_return 1 )
"""


def sim_of(body: str, kernels: str) -> Simulation:
    return Simulation(load_world_text(HEAD + body), seed=0, kernels=kernels)


@pytest.fixture(params=["numpy", "numba"])
def kernels(request) -> str:
    return request.param


def test_the_first_robot_in_order_takes_the_free_cells(kernels: str) -> None:
    # Head on, a gap that one step closes: robot 0 moves first into it, robot 1 then meets robot 0.
    sim = sim_of("box( pose [1.005 1.005 0 0] )\nbox( pose [1.265 1.005 0 180] )\n", kernels)
    sim.set_velocity(0, 0.5, 0.0, 0.0)
    sim.set_velocity(1, 0.5, 0.0, 0.0)
    sim.step()
    assert sim.stalled.tolist() == [False, True]
    assert sim.true_poses[0, 0] == pytest.approx(1.055)
    assert sim.true_poses[1, 0] == 1.265  # a refused move leaves the pose as it was


def test_a_robot_not_yet_moved_stands_where_the_layer_saw_it_two_updates_ago(kernels: str) -> None:
    # Robot 0 follows robot 1 at the same speed. In update 1 (layer 1) robot 1 has never been drawn into
    # layer 1 since the start: robot 0 meets it there, although robot 1 has moved on by then.
    sim = sim_of("box( pose [1.005 1.005 0 0] )\nbox( pose [1.285 1.005 0 0] )\n", kernels)
    sim.set_velocity(0, 0.5, 0.0, 0.0)
    sim.set_velocity(1, 0.5, 0.0, 0.0)
    sim.step()
    assert sim.stalled.tolist() == [False, False]
    sim.step()
    assert sim.stalled.tolist() == [True, False]
    assert sim.true_poses[0, 0] == pytest.approx(1.055)
    assert sim.true_poses[1, 0] == pytest.approx(1.385)


def test_a_move_is_tested_at_its_end_pose_only(kernels: str) -> None:
    # 0.3 m in one step across a wall 0.04 m thick: Stage does not sweep the path, the robot lands beyond.
    world = HEAD.replace("interval_sim 100", "interval_sim 300").replace("size [0.2 0.2 0.2]", "size [0.1 0.1 0.2]")
    sim = Simulation(load_world_text(world + "wall( size [0.04 2 1] pose [2 1 0 0] )\nbox( pose [1.85 1 0 0] )\n"),
                     seed=0, kernels=kernels)
    sim.set_velocity(0, 1.0, 0.0, 0.0)
    sim.step()
    assert not sim.stalled[0]
    assert sim.true_poses[0, 0] == pytest.approx(2.15)


def test_a_refused_robot_keeps_its_pose_and_a_standing_one_keeps_its_stall_flag(kernels: str) -> None:
    sim = sim_of("wall( size [0.04 2 1] pose [2 1 0 0] )\nbox( pose [1.86 1 0 0] )\n", kernels)
    sim.set_velocity(0, 0.5, 0.0, 0.0)
    sim.step()
    assert sim.stalled[0]
    np.testing.assert_array_equal(sim.true_poses[0], [1.86, 1.0, 0.0])
    sim.set_velocity(0, 0.0, 0.0, 0.0)
    sim.step()
    assert sim.stalled[0]  # Stage's Move returns before touching the flag when the velocity is zero
    sim.set_velocity(0, -0.5, 0.0, 0.0)
    sim.step()
    assert not sim.stalled[0]
