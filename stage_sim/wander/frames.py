"""Planar geometry for the wanderer: points seen from one robot pose expressed from another, and point sets
thinned to one point per grid cell."""

from __future__ import annotations

import math

import numpy as np


def compose(pose: tuple[float, float, float], points: np.ndarray, inverse: bool = False) -> np.ndarray:
    """Points (P, 2) given in the frame at ``pose`` in the outer frame, or the reverse with ``inverse``."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    if inverse:
        dx, dy = points[:, 0] - pose[0], points[:, 1] - pose[1]
        return np.stack([c * dx + s * dy, -s * dx + c * dy], axis=-1)
    return np.stack([pose[0] + c * points[:, 0] - s * points[:, 1], pose[1] + s * points[:, 0] + c * points[:, 1]], -1)


def first_per_cell(points: np.ndarray, cell: float) -> np.ndarray:
    """Indices of the first point in each occupied grid cell of size ``cell``, ordered by cell (row-major):
    what ``np.unique(cells, axis=0, return_index=True)`` gives, through a one-dimensional key (faster)."""
    cells = np.floor(points / cell).astype(np.int64)
    if not len(cells):
        return np.zeros(0, dtype=np.int64)
    low = cells.min(axis=0)
    span = cells[:, 1].max() - low[1] + 1
    return np.unique((cells[:, 0] - low[0]) * span + (cells[:, 1] - low[1]), return_index=True)[1]
