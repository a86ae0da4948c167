"""What the wanderer takes for moving: things that came in where a recent scan saw free space; and what it
takes for another robot: something that moved in where its map had seen nothing before."""

from __future__ import annotations

import copy

import numpy as np

from stage_sim.wander.frames import compose
from stage_sim.wander.obstacle_memory import MOVER_NEAR, MOVER_S, SLOW_RANGE, SLOW_SCANS, ObstacleMemory
from stage_sim.wander.seen_space import SeenSpace
from tests.wander.test_reactive import scan_of_segments

ODOMETRY = np.zeros(2)


def moving_flags(memory: ObstacleMemory, segments: list, pose: tuple = (0.0, 0.0, 0.0)) -> np.ndarray:
    points, _, moving, _ = memory.update(scan_of_segments(segments), pose, ODOMETRY)
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


def look(memory: ObstacleMemory, seen: SeenSpace, segments: list, time: float) -> tuple[np.ndarray, np.ndarray]:
    """One scan from the origin: into the memory (robots told by ``seen``), then into the map, as the wanderer
    does; the hit points and which of them are taken for another robot."""
    reading = scan_of_segments(segments)
    points, _, _, robot = memory.update(reading, (0.0, 0.0, 0.0), ODOMETRY, time, seen.never_occupied)
    hit = reading.hits()
    ends = reading.beam_ends(np.where(hit, np.asarray(reading.ranges), reading.range_max))
    seen.observe(np.array(reading.laser_pose[:2]), compose((0.0, 0.0, 0.0), ends), hit)
    return points[: hit.sum()], robot[: hit.sum()]


ROOM = [(3.0, -2.0, 3.0, 2.0), (-1.0, 1.2, 3.0, 1.2), (-1.0, -0.9, 3.0, -0.9)]


def side_on(x: float, y: float) -> list[tuple[float, float, float, float]]:
    """Another robot's body (0.4 x 0.3 m) centred at (x, y), side on to the laser."""
    return [(x - 0.15, y - 0.2, x - 0.15, y + 0.2), (x - 0.15, y - 0.2, x + 0.15, y - 0.2),
            (x - 0.15, y + 0.2, x + 0.15, y + 0.2)]


def test_a_robot_that_drove_into_space_seen_free_is_a_robot_while_it_stands_until_mover_s_passes() -> None:
    memory, seen = ObstacleMemory(radius=1.5), SeenSpace()
    t = 0.0
    for _ in range(3):
        points, robot = look(memory, seen, ROOM, t)
        assert not robot.any()  # walls are never robots
        t += 0.1
    arrived = t
    for k in range(3):  # it drives in from the left, 7 cm a scan, and stops 1 m ahead
        points, robot = look(memory, seen, ROOM + side_on(1.0, 0.14 - 0.07 * k), t)
        t += 0.1
    body = np.hypot(points[:, 0] - 1.0, points[:, 1]) < 0.3
    assert robot[body].all() and not robot[~body].any()
    while t < arrived + MOVER_S - 0.05:  # standing still: no longer moving, still a robot
        points, robot = look(memory, seen, ROOM + side_on(1.0, 0.0), t)
        t += 0.1
    assert robot[np.hypot(points[:, 0] - 1.0, points[:, 1]) < 0.3].all()
    while t < arrived + MOVER_S + 0.3:
        points, robot = look(memory, seen, ROOM + side_on(1.0, 0.0), t)
        t += 0.1
    assert not robot.any()


def test_a_wall_taken_for_moving_where_the_map_saw_it_before_is_no_robot() -> None:
    """Quantisation at a doorway's jamb can make a wall look as if it moved in; the map knows it was there."""
    memory, seen = ObstacleMemory(radius=1.5), SeenSpace()
    look(memory, seen, [*ROOM, (0.6, 0.25, 1.2, 0.25)], 0.0)
    jamb = [*ROOM, (0.55, 0.25, 1.2, 0.25), (0.55, 0.2, 0.55, 0.25)]  # 5 cm nearer: what quantisation can do
    assert moving_flags(copy.deepcopy(memory), jamb).any()
    _, robot = look(memory, seen, jamb, 0.1)
    assert not robot.any()


def test_hits_near_a_robot_seen_lately_count_as_its_body_farther_ones_do_not() -> None:
    memory, seen = ObstacleMemory(radius=1.5), SeenSpace()
    room = [*ROOM, (1.0, -0.6, 1.6, -0.6)]  # a wall beside where the robot will stop
    look(memory, seen, room, 0.0)
    look(memory, seen, room + side_on(1.0, 0.0), 0.1)
    points, robot = look(memory, seen, room + side_on(1.0, 0.0), 0.2)
    assert robot[np.hypot(points[:, 0] - 1.0, points[:, 1]) < 0.3].all()
    far = np.hypot(points[:, 0] - 1.0, points[:, 1]) > MOVER_NEAR + 0.3
    assert far.any() and not robot[far].any()
