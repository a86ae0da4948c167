"""The obstacle points a reactive planner keeps clear of: this scan's hits plus remembered ones out of view.

The laser does not see behind the robot, yet turning in place swings the rear corners through that blind
sector; so the nearby points that have left the field of view are kept, in the odometry frame, each with a
safety allowance that grows with the odometry error accumulated since it was seen (metres driven, radians
turned), and forgotten once that allowance is too large to plan with. Points where the previous scan saw
free space are flagged as moving: something came in, such as another robot.
"""

from __future__ import annotations

import math

import numpy as np

from stage_sim.wander.arc_planner import MAX_ALLOWANCE
from stage_sim.wander.frames import compose, first_per_cell
from stage_sim.wander.laser_reading import LaserReading

MEMORY_CELL = 0.03  # m: remembered points are thinned to one per cell of this size
ODOM_DRIFT = (0.02, 0.03)  # allowance per metre driven and per radian of net turn (m/m, rad/rad) since a point was seen
MOVED, MOVED_PER_M = 0.03, 0.01  # m (+ per m of range) inside last scan's free space for a point to be moving


class ObstacleMemory:
    """Remembered obstacle points within ``radius`` m of the robot, and the previous scan to spot movers."""

    def __init__(self, radius: float) -> None:
        self.radius = radius
        self._memory = np.zeros((0, 4))  # x, y (odometry frame), odometry travel and turn when seen
        self._last_scan: tuple | None = None  # the previous scan: laser pose (odometry frame) and ranges

    def update(
        self, reading: LaserReading, pose: tuple[float, float, float], odometry: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Obstacle points in the robot frame (this scan, then remembered ones out of view), their allowances,
        and which of them are moving (nearer than the last scan put anything along their beam)."""
        seen, beams = reading.points(), reading.hits()
        moving = self._approaching(reading, pose)[beams]
        remembered = compose(pose, self._memory[:, :2], inverse=True)
        keep = reading.outside_view(remembered)
        points = np.concatenate([seen, remembered[keep]])
        stamps = np.concatenate([np.tile(odometry, (len(seen), 1)), self._memory[keep, 2:]])
        distance = np.hypot(points[:, 0], points[:, 1])
        drift = np.abs(odometry - stamps) * ODOM_DRIFT
        allowance = drift[:, 0] + drift[:, 1] * distance
        trusted = allowance <= MAX_ALLOWANCE
        moving = np.concatenate([moving, np.zeros(len(points) - len(seen), dtype=bool)])[trusted]
        points, allowance, stamps, distance = points[trusted], allowance[trusted], stamps[trusted], distance[trusted]
        near = distance < self.radius
        world = compose(pose, points[near])
        unique = first_per_cell(world, MEMORY_CELL)
        unique.sort()  # the first of a cell is the freshest
        self._memory = np.concatenate([world[unique], stamps[near][unique]], axis=1)
        return points, allowance, moving

    def _approaching(self, reading: LaserReading, pose: tuple) -> np.ndarray:
        """Per beam: whether it hits something where the previous scan saw free space (its beam, or a
        neighbour, reached further), i.e. something that moved in, such as another robot."""
        ranges = np.asarray(reading.ranges, dtype=np.float64)
        x, y, yaw = reading.laser_pose
        here = (pose[0] + math.cos(pose[2]) * x - math.sin(pose[2]) * y,
                pose[1] + math.sin(pose[2]) * x + math.cos(pose[2]) * y, pose[2] + yaw)
        previous, self._last_scan = self._last_scan, (here, np.where(reading.hits(), ranges, reading.range_max))
        if previous is None:
            return np.zeros(len(ranges), dtype=bool)
        (px, py, pyaw), before = previous
        angles = here[2] + reading.angle_min + np.arange(len(ranges)) * reading.angle_increment
        end = np.stack([here[0] + ranges * np.cos(angles), here[1] + ranges * np.sin(angles)], axis=-1)
        seen_from = compose((px, py, pyaw), end, inverse=True)  # the hit points in the previous laser frame
        distance = np.hypot(seen_from[:, 0], seen_from[:, 1])
        index = np.rint((np.arctan2(seen_from[:, 1], seen_from[:, 0]) - reading.angle_min)
                        / reading.angle_increment).astype(np.int64)
        padded = np.concatenate([[np.inf], before, [np.inf]])
        inside = (index >= 0) & (index < len(before))
        index = np.clip(index, 0, len(before) - 1) + 1
        free_to = np.minimum(np.minimum(padded[index - 1], padded[index]), padded[index + 1])
        nearer = inside & reading.hits() & (distance < free_to - (MOVED + MOVED_PER_M * distance))
        nearer = np.concatenate([[False], nearer, [False]])
        return nearer[1:-1] & (nearer[:-2] | nearer[2:])  # a lone beam is an edge effect, not a body
