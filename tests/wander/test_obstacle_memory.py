"""What the wanderer takes for moving: things that came in where a recent scan saw free space."""

from __future__ import annotations

import numpy as np

from stage_sim.wander.obstacle_memory import SLOW_RANGE, SLOW_SCANS, ObstacleMemory
from tests.wander.test_reactive import scan_of_segments

ODOMETRY = np.zeros(2)


def moving_flags(memory: ObstacleMemory, segments: list, pose: tuple = (0.0, 0.0, 0.0)) -> np.ndarray:
    points, _, moving = memory.update(scan_of_segments(segments), pose, ODOMETRY)
    return moving[: len(points)]


def robot_rear(x: float) -> list[tuple[float, float, float, float]]:
    """The rear face of another robot (0.3 m wide) at ``x`` m ahead, square to the laser."""
    return [(x, -0.15, x, 0.15)]


def test_a_robot_backing_in_at_walking_pace_is_moving_once_half_a_second_shows_it() -> None:
    memory = ObstacleMemory(radius=1.5)
    flags = [moving_flags(memory, robot_rear(1.0 - 0.015 * k)) for k in range(SLOW_SCANS + 2)]
    # 15 mm per scan is within the per-scan quantisation margin: only the scan of half a second ago tells,
    # and the next scan confirms it.
    assert not any(f.any() for f in flags[: SLOW_SCANS + 1])
    assert flags[SLOW_SCANS + 1].all()


def test_a_wall_nearer_than_half_a_second_ago_for_one_scan_only_is_no_mover() -> None:
    """What quantisation does to a wall seen from two poses in turn: it must not stop a robot turning to and fro."""
    memory = ObstacleMemory(radius=1.5)
    walls = [1.0] * SLOW_SCANS + [0.98, 0.96, 1.0, 0.98, 0.96, 1.0]
    assert not any(moving_flags(memory, robot_rear(x)).any() for x in walls)


def test_a_slow_robot_beyond_the_slow_range_is_not_flagged() -> None:
    memory = ObstacleMemory(radius=1.5)
    start = SLOW_RANGE + 0.5
    flags = [moving_flags(memory, robot_rear(start - 0.015 * k)) for k in range(SLOW_SCANS + 2)]
    assert not any(f.any() for f in flags)


def test_walls_seen_while_driving_at_full_speed_are_never_moving() -> None:
    memory = ObstacleMemory(radius=1.5)
    room = [(3.0, -2.0, 3.0, 2.0), (-1.0, 1.2, 3.0, 1.2), (-1.0, -0.9, 3.0, -0.9), (1.4, 0.5, 1.8, 0.5)]
    for k in range(20):  # 0.07 m per scan towards the far wall; the segments are in the robot frame
        x = 0.07 * k
        shifted = [(x0 - x, y0, x1 - x, y1) for x0, y0, x1, y1 in room]
        assert not moving_flags(memory, shifted, pose=(x, 0.0, 0.0)).any()


def test_a_robot_crossing_at_speed_is_moving_from_the_next_scan() -> None:
    memory = ObstacleMemory(radius=1.5)
    moving_flags(memory, robot_rear(2.0))
    assert moving_flags(memory, robot_rear(1.9)).all()
