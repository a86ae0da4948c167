"""The core driver hands the wanderer what the ``wander`` node receives from stageros over ROS."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stage_sim.runs.driver import WanderDriver
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world, load_world_text

REPO = Path(__file__).resolve().parents[2]


def test_a_beam_that_reached_its_range_limit_is_no_obstacle_point() -> None:
    sim = Simulation(load_world(REPO / "worlds" / "rooms.world"), seed=1)
    reading = WanderDriver(sim, seed=1).reading(0)
    ranges = np.asarray(sim.scans[0][0].ranges)
    misses = ranges == np.float32(sim.robots[0].rangers[0].sensor.range_max)
    assert misses.any()  # the start pose looks down a room longer than the laser's range
    assert not reading.hits()[misses].any()
    assert reading.hits()[~misses].all()
    assert len(reading.points()) == int((~misses).sum())


def test_scan_fields_are_the_float32_values_a_laser_scan_carries() -> None:
    sim = Simulation(load_world(REPO / "worlds" / "corridor.world"), seed=1)
    reading = WanderDriver(sim, seed=1).reading(0)
    sensor = sim.robots[0].rangers[0].sensor
    for value, exact in ((reading.angle_min, -sensor.fov / 2), (reading.range_max, sensor.range_max),
                         (reading.angle_increment, sensor.fov / (sensor.samples - 1))):
        assert value == float(np.float32(exact))
    assert reading.laser_pose[:2] == (sim.robots[0].rangers[0].pose.x, sim.robots[0].rangers[0].pose.y)


def test_only_robots_with_a_holonomic_drive_get_a_wanderer_that_moves_sideways() -> None:
    world = load_world_text("""
define laser ranger ( sensor( range [0 4] fov 180 samples 9 ) )
define bot position ( size [0.4 0.3 0.2] laser( ) )
bot( pose [1 1 0 0] drive "diff" )
bot( pose [3 1 0 0] drive "omni" )
bot( pose [5 1 0 0] drive "car" )
""", "drives.world")
    driver = WanderDriver(Simulation(world, seed=1, kernels="numpy"), seed=1)
    assert [driver.wanderers[i].config.holonomic for i in range(3)] == [False, True, False]
