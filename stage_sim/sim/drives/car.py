"""``drive "car"``: Stage's car-like (bicycle) model. The command (gx, ·, ga) is a speed and a steering angle;
the body moves at (gx·cos ga, 0, gx·sin ga / wheelbase), ``wheelbase`` from the position model."""

from __future__ import annotations

import numpy as np

HOLONOMIC = False
STEERED = True


def velocities(commands: np.ndarray, wheelbases: np.ndarray) -> np.ndarray:
    """Body velocities for commands (N, 3) = (speed, ignored, steering angle) and ``wheelbases`` (N,)."""
    speed, steer = commands[:, 0], commands[:, 2]
    return np.stack([speed * np.cos(steer), np.zeros_like(speed), speed * np.sin(steer) / wheelbases], axis=1)


def compiled_velocities(commands: np.ndarray, rows: np.ndarray, wheelbases: np.ndarray, cos_steer: np.ndarray,
                        sin_steer: np.ndarray, out: np.ndarray) -> None:
    """:func:`velocities` of the robots ``rows`` into ``out`` (compiled by :mod:`stage_sim.sim.motion_kernels`)."""
    for i in rows:
        out[i, 0] = commands[i, 0] * cos_steer[i]
        out[i, 1] = 0.0
        out[i, 2] = commands[i, 0] * sin_steer[i] / wheelbases[i]
