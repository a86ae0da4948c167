"""``drive "omni"``: a holonomic base follows all three components of its command (gx, gy, ga)."""

from __future__ import annotations

import numpy as np

HOLONOMIC = True
STEERED = False


def velocities(commands: np.ndarray, wheelbases: np.ndarray) -> np.ndarray:
    """Body velocities (gx, gy, ga) for commands (N, 3); ``wheelbases`` is unused (car only)."""
    return commands.copy()


def compiled_velocities(commands: np.ndarray, rows: np.ndarray, wheelbases: np.ndarray, cos_steer: np.ndarray,
                        sin_steer: np.ndarray, out: np.ndarray) -> None:
    """:func:`velocities` of the robots ``rows`` into ``out`` (compiled by :mod:`stage_sim.sim.motion_kernels`)."""
    for i in rows:
        out[i, 0] = commands[i, 0]
        out[i, 1] = commands[i, 1]
        out[i, 2] = commands[i, 2]
