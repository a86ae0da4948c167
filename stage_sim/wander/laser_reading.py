"""One laser scan as a planner on the robot uses it: hit points in the robot frame and the blind sector."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


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

    def outside_view(self, points: np.ndarray) -> np.ndarray:
        """Which robot-frame points lie outside the laser's field of view (the blind sector)."""
        x, y, yaw = self.laser_pose
        half_fov = (len(self.ranges) - 1) * self.angle_increment / 2
        off_axis = wrap(np.arctan2(points[:, 1] - y, points[:, 0] - x) - yaw - self.angle_min - half_fov)
        return np.abs(off_axis) > half_fov + 1e-3


def wrap(angle: float | np.ndarray) -> float | np.ndarray:
    """Angle(s) in [-π, π)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi
