"""``drive "diff"`` (Stage's default): a differential drive follows the forward speed and the turn rate of its
command (gx, ga) and never moves sideways, whatever gy says."""

from __future__ import annotations

import numpy as np

HOLONOMIC = False
STEERED = False


def velocities(commands: np.ndarray, wheelbases: np.ndarray) -> np.ndarray:
    """Body velocities (gx, 0, ga) for commands (N, 3); ``wheelbases`` is unused (car only)."""
    velocity = commands.copy()
    velocity[:, 1] = 0.0
    return velocity


def compiled_velocities(commands: np.ndarray, rows: np.ndarray, wheelbases: np.ndarray, cos_steer: np.ndarray,
                        sin_steer: np.ndarray, out: np.ndarray) -> None:
    """:func:`velocities` of the robots ``rows`` into ``out`` (compiled by :mod:`stage_sim.sim.motion_kernels`)."""
    for i in rows:
        out[i, 0] = commands[i, 0]
        out[i, 1] = 0.0
        out[i, 2] = commands[i, 2]
