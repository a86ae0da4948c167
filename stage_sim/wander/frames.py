"""Planar frames for the wanderer: points seen from one robot pose expressed from another."""

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
