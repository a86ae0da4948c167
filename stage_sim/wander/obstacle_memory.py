"""The obstacle points a reactive planner keeps clear of: this scan's hits plus remembered ones out of view.

The laser does not see behind the robot, yet turning in place swings the rear corners through that blind
sector; so the nearby points that have left the field of view are kept, in the odometry frame, each with a
safety allowance that grows with the odometry error accumulated since it was seen (metres driven, radians
turned), and forgotten once that allowance is too large to plan with. Points where the previous scan saw
free space are flagged as moving: something came in, such as another robot. Near points are also held
against the scan of SLOW_SCANS scans ago (and must pass that twice in a row): a robot reversing blind at
0.15 m/s moves too little from one scan to the next to be told from sensor quantisation, yet would run into
a robot that took it for a wall. A moving hit on ground the map of seen space never saw occupied marks the place
as another robot's for MOVER_S, and hits near such a place are taken for its body: the planner gives them a
wider berth, since a robot may back up blind at any moment.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable

import numpy as np

from stage_sim.wander.arc_planner import MAX_ALLOWANCE
from stage_sim.wander.frames import compose, first_per_cell
from stage_sim.wander.laser_reading import LaserReading

MEMORY_CELL = 0.03  # m: remembered points are thinned to one per cell of this size
ODOM_DRIFT = (0.02, 0.03)  # allowance per metre driven and per radian of net turn (m/m, rad/rad) since a point was seen
MOVED, MOVED_PER_M = 0.03, 0.01  # m (+ per m of range) inside last scan's free space for a point to be moving
SLOW_SCANS = 5  # scans back (0.5 s at 10 Hz) of the scan that near points are also held against
SLOW_RANGE = 1.5  # m: points this near are checked for slow movers (farther ones cannot reach the body in time)
SLOW_CONFIRM = 0.1  # m: a slow mover counts when the previous scan found one this near it too
MOVER_S = 10.0  # s a place where another robot was seen is remembered
MOVER_NEAR = 0.3  # m: hits this near such a place are taken for another robot's body
MOVER_CELL = 0.05  # m: the places are thinned to the newest per cell of this size


class ObstacleMemory:
    """Remembered obstacle points within ``radius`` m of the robot, and the previous scan to spot movers."""

    def __init__(self, radius: float) -> None:
        self.radius = radius
        self._memory = np.zeros((0, 4))  # x, y (odometry frame), odometry travel and turn when seen
        # The latest scans, oldest first: laser pose (odometry frame) and ranges (misses at range_max).
        self._scans: deque[tuple] = deque(maxlen=SLOW_SCANS)
        self._slow = np.zeros((0, 2))  # where the previous scan found slow movers (odometry frame)
        self._movers = np.zeros((0, 3))  # where something was seen moving in lately: x, y (odometry frame), time

    def update(
        self, reading: LaserReading, pose: tuple[float, float, float], odometry: np.ndarray, time: float = 0.0,
        new: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Obstacle points in the robot frame (this scan, then remembered ones out of view), their allowances,
        which of them are moving (nearer than the last scan put anything along their beam) and which are taken
        for another robot's body: moving hits where ``new`` says nothing was before (odometry frame; None:
        none is) mark the place as another robot's for MOVER_S, and hits near such a place count."""
        seen, beams = reading.points(), reading.hits()
        moving = self._approaching(reading, pose)[beams]
        world = compose(pose, seen)
        mover = np.zeros(len(seen), dtype=bool)
        if new is not None and moving.any():
            mover[moving] = new(world[moving])
        robot = self._near_movers(world, mover, time)
        remembered = compose(pose, self._memory[:, :2], inverse=True)
        keep = reading.outside_view(remembered)
        points = np.concatenate([seen, remembered[keep]])
        stamps = np.concatenate([np.tile(odometry, (len(seen), 1)), self._memory[keep, 2:]])
        distance = np.hypot(points[:, 0], points[:, 1])
        drift = np.abs(odometry - stamps) * ODOM_DRIFT
        allowance = drift[:, 0] + drift[:, 1] * distance
        trusted = allowance <= MAX_ALLOWANCE
        moving = np.concatenate([moving, np.zeros(len(points) - len(seen), dtype=bool)])[trusted]
        robot = np.concatenate([robot, np.zeros(len(points) - len(seen), dtype=bool)])[trusted]
        points, allowance, stamps, distance = points[trusted], allowance[trusted], stamps[trusted], distance[trusted]
        near = distance < self.radius
        world = compose(pose, points[near])
        unique = first_per_cell(world, MEMORY_CELL)
        unique.sort()  # the first of a cell is the freshest
        self._memory = np.concatenate([world[unique], stamps[near][unique]], axis=1)
        return points, allowance, moving, robot

    def _near_movers(self, world: np.ndarray, mover: np.ndarray, time: float) -> np.ndarray:
        """Per hit (odometry frame): whether it lies within MOVER_NEAR of a place where another robot was seen
        within MOVER_S (this scan's ``mover`` hits included), remembering this scan's."""
        movers = np.concatenate([np.column_stack([world[mover], np.full(int(mover.sum()), time)]),
                                 self._movers[time - self._movers[:, 2] < MOVER_S]])  # newest first
        self._movers = movers[np.sort(first_per_cell(movers[:, :2], MOVER_CELL))]
        return _near_any(world, self._movers[:, :2], MOVER_NEAR)

    def _approaching(self, reading: LaserReading, pose: tuple) -> np.ndarray:
        """Per beam: whether it hits something where the previous scan saw free space (its beam, or a
        neighbour, reached further), or, within SLOW_RANGE, where the scan SLOW_SCANS back did and the
        previous scan found the same: something that moved in, such as another robot. (A wall seen from two
        poses can pass the second test once, by quantisation: a robot turning to and fro between those poses
        would take it for a mover every other scan and dither for ever; a real mover passes it every scan.)"""
        ranges = np.asarray(reading.ranges, dtype=np.float64)
        x, y, yaw = reading.laser_pose
        here = (pose[0] + math.cos(pose[2]) * x - math.sin(pose[2]) * y,
                pose[1] + math.sin(pose[2]) * x + math.cos(pose[2]) * y, pose[2] + yaw)
        hits = reading.hits()
        nearer = np.zeros(len(ranges), dtype=bool)
        if self._scans:
            angles = here[2] + reading.angle_min + np.arange(len(ranges)) * reading.angle_increment
            end = np.stack([here[0] + ranges * np.cos(angles), here[1] + ranges * np.sin(angles)], axis=-1)
            nearer = hits & _inside_free_space(end, reading, *self._scans[-1])
            if len(self._scans) == SLOW_SCANS:
                slow = hits & (ranges < SLOW_RANGE) & _inside_free_space(end, reading, *self._scans[0])
                nearer |= slow & _near_any(end, self._slow, SLOW_CONFIRM)
                self._slow = end[slow]
        self._scans.append((here, np.where(hits, ranges, reading.range_max)))
        nearer = np.concatenate([[False], nearer, [False]])
        return nearer[1:-1] & (nearer[:-2] | nearer[2:])  # a lone beam is an edge effect, not a body


def _near_any(points: np.ndarray, others: np.ndarray, reach: float) -> np.ndarray:
    """Per point: whether any of ``others`` lies within ``reach`` of it."""
    if not len(points) or not len(others):
        return np.zeros(len(points), dtype=bool)
    gaps = np.hypot(points[:, None, 0] - others[None, :, 0], points[:, None, 1] - others[None, :, 1])
    return gaps.min(axis=1) < reach


def _inside_free_space(end: np.ndarray, reading: LaserReading, laser: tuple, before: np.ndarray) -> np.ndarray:
    """Per hit point (odometry frame): whether a scan taken from ``laser`` with ``before`` ranges saw free space
    there (its beam, or a neighbour, reached further by the quantisation margin)."""
    seen_from = compose(laser, end, inverse=True)  # the hit points in that scan's laser frame
    distance = np.hypot(seen_from[:, 0], seen_from[:, 1])
    index = np.rint((np.arctan2(seen_from[:, 1], seen_from[:, 0]) - reading.angle_min)
                    / reading.angle_increment).astype(np.int64)
    padded = np.concatenate([[np.inf], before, [np.inf]])
    inside = (index >= 0) & (index < len(before))
    index = np.clip(index, 0, len(before) - 1) + 1
    free_to = np.minimum(np.minimum(padded[index - 1], padded[index]), padded[index + 1])
    return inside & (distance < free_to - (MOVED + MOVED_PER_M * distance))
