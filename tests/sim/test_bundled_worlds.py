"""Every bundled world loads and means what its comments say."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.bundled import bundled_worlds, data_root
from stage_sim.worldfile.loader import load_world

EXPECTED = {
    "rooms.world": (1, "diff", (11.1, 9.2, 90)),
    "rooms_yaml.world": (1, "diff", (11.1, 9.2, 90)),
    "omni.world": (1, "omni", (11.1, 9.2, 90)),
    "multi_robots.world": (4, "diff", (11.1, 9.2, 90)),
    "corridor.world": (1, "diff", (1.5, 5.0, 0)),
}


def test_the_expected_worlds_are_bundled() -> None:
    assert set(EXPECTED) <= set(bundled_worlds())


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_bundled_world_robots_and_start_pose(name: str) -> None:
    count, drive, (x, y, yaw_deg) = EXPECTED[name]
    world = load_world(data_root() / "worlds" / name)
    robots = world.robots()
    assert len(robots) == count
    assert robots[0].position.drive == drive
    assert (robots[0].pose.x, robots[0].pose.y, robots[0].pose.yaw) == pytest.approx((x, y, math.radians(yaw_deg)))
    assert not [w for w in world.warnings if "unknown" in w.message]


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_bundled_robots_start_free_and_see_walls(name: str) -> None:
    sim = Simulation.from_world(data_root() / "worlds" / name, seed=0)
    for scans in sim.scans:
        ranges = scans[0].ranges
        assert len(ranges) == 240
        assert ranges.min() > 0.3  # free start with room around the body
        assert (ranges < 5.6).any()  # the walls are in view
    for i in range(len(sim.robots)):
        sim.set_velocity(i, 0.1, 0.0, 0.0)
    sim.step()
    assert not sim.stalled.any()


def test_course_robot_matches_the_tutorial() -> None:
    robot = load_world(data_root() / "worlds" / "rooms.world").robots()[0]
    assert robot.size == pytest.approx((0.4, 0.3, 0.2))
    assert robot.position.localization == "odom"
    assert robot.position.odom_error == pytest.approx((0.03, 0.03, 0.0, math.radians(0.05)))
    assert len(robot.blocks) >= 3
    (laser,) = [c for c in robot.children if c.type == "ranger"]
    sensor = laser.sensors[0]
    assert (sensor.samples, sensor.range_max) == (240, pytest.approx(5.6))
    assert sensor.fov == pytest.approx(math.radians(240))
    assert (laser.pose.x, laser.pose.z) == pytest.approx((0.23, -0.15))


def test_yaml_world_matches_the_bitmap_world() -> None:
    bitmap = Simulation.from_world(data_root() / "worlds" / "rooms.world").static
    yaml = Simulation.from_world(data_root() / "worlds" / "rooms_yaml.world").static
    assert bitmap.shape == yaml.shape and bitmap.origin_xy == yaml.origin_xy
    differ = np.count_nonzero(bitmap.occupied != yaml.occupied)
    # only the outermost cells differ (Stage's boundary walls and pixel-centre rounding at the border)
    assert differ < 0.03 * bitmap.occupied_cell_count


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_every_robot_starts_well_clear_of_the_map(name: str) -> None:
    world = load_world(data_root() / "worlds" / name)
    (floor,) = [m for m in world.models if m.bitmap is not None]
    bitmap = floor.bitmap
    assert bitmap is not None
    height, width = bitmap.occupied.shape
    if bitmap.grid is not None:  # map_server placement: the YAML origin in the model frame
        resolution = bitmap.grid.resolution
        left, bottom = floor.pose.x + bitmap.grid.origin[0], floor.pose.y + bitmap.grid.origin[1]
    else:  # Stage placement: the (full, outer-walled) image stretched to size and centred on the pose
        resolution = floor.size[0] / width
        assert floor.size[1] / height == pytest.approx(resolution)
        left, bottom = floor.pose.x - floor.size[0] / 2, floor.pose.y - floor.size[1] / 2
    rows, cols = np.nonzero(bitmap.occupied)
    x0, y1 = left + cols * resolution, bottom + (height - rows) * resolution
    robots = world.robots()
    for robot in robots:
        dx = np.maximum(np.maximum(x0 - robot.pose.x, robot.pose.x - x0 - resolution), 0.0)
        dy = np.maximum(np.maximum(y1 - resolution - robot.pose.y, robot.pose.y - y1), 0.0)
        assert np.sqrt(dx * dx + dy * dy).min() >= 0.45, robot.name
    for i, a in enumerate(robots):
        for b in robots[i + 1 :]:
            assert math.hypot(a.pose.x - b.pose.x, a.pose.y - b.pose.y) > 2.0
