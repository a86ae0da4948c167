"""Where a robot has been: the last time each cell of a coarse, growing grid came within reach of it."""

from __future__ import annotations

import math

import numpy as np


class VisitMap:
    """When each cell of a coarse grid (odometry frame, growing as needed) last came within reach of the robot."""

    def __init__(self, cell: float = 0.5, reach: float = 1.0) -> None:
        self.cell = cell
        r = math.ceil(reach / cell)
        di, dj = np.meshgrid(np.arange(-r, r + 1), np.arange(-r, r + 1), indexing="ij")
        inside = np.hypot(di, dj) * cell <= reach
        self._disc = (di[inside], dj[inside])
        self._low = np.zeros(2, dtype=np.int64)
        self.times = np.full((0, 0), -np.inf)

    def stamp(self, x: float, y: float, time: float) -> None:
        """Mark the cells within reach of (x, y) as visited at ``time``."""
        i, j = math.floor(x / self.cell), math.floor(y / self.cell)
        r = int(self._disc[0].max())
        low, high = self._low, self._low + self.times.shape
        if i - r < low[0] or j - r < low[1] or i + r >= high[0] or j + r >= high[1]:
            new_low = np.minimum(low, (i - r - 20, j - r - 20))
            new_high = np.maximum(high, (i + r + 21, j + r + 21))
            grown = np.full(new_high - new_low, -np.inf)
            offset = low - new_low
            grown[offset[0]: offset[0] + self.times.shape[0], offset[1]: offset[1] + self.times.shape[1]] = self.times
            self.times, self._low = grown, new_low
        self.times[self._disc[0] + i - self._low[0], self._disc[1] + j - self._low[1]] = time

    def mark(self, xy: np.ndarray, time: float) -> None:
        """Mark the cells of points (P, 2) already in the grid as visited (given up on) at ``time``."""
        index = np.floor(xy / self.cell).astype(np.int64) - self._low
        index = index[np.all((index >= 0) & (index < self.times.shape), axis=-1)]
        self.times[index[:, 0], index[:, 1]] = time

    def visited_since(self, xy: np.ndarray, since: float) -> np.ndarray:
        """Whether each point (..., 2) lies in a cell visited at or after ``since``."""
        index = np.floor(xy / self.cell).astype(np.int64) - self._low
        inside = np.all((index >= 0) & (index < self.times.shape), axis=-1)
        clipped = np.clip(index, 0, np.maximum(np.array(self.times.shape) - 1, 0))
        return inside & (self.times[clipped[..., 0], clipped[..., 1]] >= since) if self.times.size else inside
