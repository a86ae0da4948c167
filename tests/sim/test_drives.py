"""The drive registry: every drive a world file may name has its model, and robots step one drive group at a time."""

from __future__ import annotations

import pkgutil

import numpy as np

from stage_sim.sim import drives
from stage_sim.sim.drives import DRIVES, group_by_drive
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.drive_names import DRIVE_NAMES
from stage_sim.worldfile.loader import load_world_text


def test_every_drive_a_world_file_accepts_has_a_model_and_every_model_a_name() -> None:
    modules = {module.name for module in pkgutil.iter_modules(drives.__path__)}
    assert list(DRIVES) == list(DRIVE_NAMES)
    assert modules == set(DRIVE_NAMES)  # a drive module the world file cannot name would never run
    assert all(drive.name == name for name, drive in DRIVES.items())


def test_only_the_omni_drive_moves_sideways() -> None:
    assert {name for name, drive in DRIVES.items() if drive.holonomic} == {"omni"}


def test_groups_hold_each_drives_robots_in_robot_order_and_skip_absent_drives() -> None:
    groups = group_by_drive(["car", "diff", "car", "diff", "diff"])
    assert [group.drive.name for group in groups] == ["diff", "car"]
    assert [group.rows.tolist() for group in groups] == [[1, 3, 4], [0, 2]]
    assert all(group.rows.dtype == np.int64 for group in groups)
    assert group_by_drive([]) == ()


def test_a_robot_carries_the_model_of_its_world_file_drive() -> None:
    world = load_world_text("""
define bot position ( size [0.4 0.3 0.2] )
bot( pose [0 0 0 0] )
bot( pose [2 0 0 0] drive "omni" )
bot( pose [4 0 0 0] drive "car" )
""", "drives.world")
    sim = Simulation(world, seed=0, kernels="numpy")
    assert [robot.drive for robot in sim.robots] == [DRIVES["diff"], DRIVES["omni"], DRIVES["car"]]
