"""One laser scan as a planner on the robot uses it: hit points in the robot frame and the blind sector."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MISS = 1e9  # m standing in for a beam that hit nothing, beyond any jump from a hit


@dataclass(frozen=True)
class LaserReading:
    """One scan as the sensor reports it, plus where the laser sits on the robot (x, y, yaw)."""

    ranges: np.ndarray
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    laser_pose: tuple[float, float, float] = (0.23, 0.0, 0.0)

    def hits(self) -> np.ndarray:
        """Which beams hit something (misses report range_max, inf or NaN)."""
        ranges = np.asarray(self.ranges, dtype=np.float64)
        return np.isfinite(ranges) & (ranges >= self.range_min) & (ranges < self.range_max)

    def beam_ends(self, ranges: np.ndarray) -> np.ndarray:
        """Where each beam ends (N, 2) in the robot frame at the given ranges (one per beam)."""
        x, y, yaw = self.laser_pose
        angles = yaw + self.angle_min + np.arange(len(ranges)) * self.angle_increment
        return np.stack([x + ranges * np.cos(angles), y + ranges * np.sin(angles)], axis=-1)

    def points(self) -> np.ndarray:
        """Hit points (P, 2) in the robot frame, in beam order."""
        ranges, hit = np.asarray(self.ranges, dtype=np.float64), self.hits()
        x, y, yaw = self.laser_pose
        angles = yaw + self.angle_min + np.flatnonzero(hit) * self.angle_increment
        return np.stack([x + ranges[hit] * np.cos(angles), y + ranges[hit] * np.sin(angles)], axis=-1)

    def islands(self, widths: tuple[float, float], jump: float) -> np.ndarray:
        """Per beam: whether it hits a short island of the scan, a run of hits between ``widths`` m wide whose
        neighbours on both sides reach at least ``jump`` m further (or miss): another robot, where a wall has
        more wall beside it (and the end face of a thin wall, seen from a doorway, is narrower). Runs at the
        edges of the field of view are not islands: what lies beyond is unknown."""
        hit = self.hits()
        ranges = np.where(hit, np.asarray(self.ranges, dtype=np.float64), MISS)
        n = len(ranges)
        if n < 3:
            return np.zeros(n, dtype=bool)
        joined = hit[:-1] & hit[1:] & (np.abs(np.diff(ranges)) <= jump)
        starts = np.flatnonzero(np.concatenate([[True], ~joined]))
        ends = np.concatenate([starts[1:] - 1, [n - 1]])
        inner = (starts > 0) & (ends < n - 1)
        before = ranges[np.maximum(starts - 1, 0)]
        after = ranges[np.minimum(ends + 1, n - 1)]
        points = self.beam_ends(np.where(hit, ranges, 0.0))
        width = np.hypot(*(points[ends] - points[starts]).T)
        island = (hit[starts] & inner & (before >= ranges[starts] + jump) & (after >= ranges[ends] + jump)
                  & (width >= widths[0]) & (width <= widths[1]))
        return np.repeat(island, ends - starts + 1)

    def outside_view(self, points: np.ndarray) -> np.ndarray:
        """Which robot-frame points lie outside the laser's field of view (the blind sector)."""
        x, y, yaw = self.laser_pose
        half_fov = (len(self.ranges) - 1) * self.angle_increment / 2
        off_axis = wrap(np.arctan2(points[:, 1] - y, points[:, 0] - x) - yaw - self.angle_min - half_fov)
        return np.abs(off_axis) > half_fov + 1e-3


def wrap(angle: float | np.ndarray) -> float | np.ndarray:
    """Angle(s) in [-π, π)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi
