"""Stage's velocity-control kinematics for many robots at once (``drive`` diff / omni / car).

Per step of length ``dt`` (Stage's ``Move``), with the heading ``a`` at the start of the step::

    x' = x + vx·dt·cos a − vy·dt·sin a
    y' = y + vx·dt·sin a + vy·dt·cos a
    a' = normalize(a + normalize(va·dt))

The body velocity comes from the command (gx, gy, ga): diff (gx, 0, ga), omni (gx, gy, ga), car
(gx·cos ga, 0, gx·sin ga / wheelbase) where ga is the steering angle; each component is then clamped to the
robot's ``velocity_bounds``. There is no acceleration limit in velocity mode (Stage's behaviour).
"""

from __future__ import annotations

import numpy as np

DRIVE_CODES = {"diff": 0, "omni": 1, "car": 2}


def normalize_angle(angle: np.ndarray | float) -> np.ndarray:
    """Wrap angles to (−π, π], as Stage's ``normalize`` does."""
    wrapped = np.mod(np.asarray(angle, dtype=np.float64) + np.pi, 2.0 * np.pi) - np.pi
    return np.where(wrapped == -np.pi, np.pi, wrapped)


def body_velocity(
    commands: np.ndarray, drives: np.ndarray, wheelbases: np.ndarray, bounds: np.ndarray
) -> np.ndarray:
    """Body-frame velocities (vx, vy, va) that Stage applies for commands (gx, gy, ga).

    ``commands`` is (N, 3), ``drives`` (N,) codes from :data:`DRIVE_CODES`, ``wheelbases`` (N,) and
    ``bounds`` (N, 8) ``velocity_bounds`` (xmin xmax ymin ymax zmin zmax amin amax) in SI units.
    """
    gx, gy, ga = commands[:, 0], commands[:, 1], commands[:, 2]
    is_omni = drives == DRIVE_CODES["omni"]
    is_car = drives == DRIVE_CODES["car"]
    vx = np.where(is_car, gx * np.cos(ga), gx)
    vy = np.where(is_omni, gy, 0.0)
    va = np.where(is_car, gx * np.sin(ga) / wheelbases, ga)
    velocity = np.stack([vx, vy, va], axis=1)
    low = bounds[:, [0, 2, 6]]
    high = bounds[:, [1, 3, 7]]
    return np.clip(velocity, low, high)


def integrate(poses: np.ndarray, velocities: np.ndarray, dt: float) -> np.ndarray:
    """Poses (N, 3) = (x, y, yaw) after one explicit Euler step with body velocities (N, 3)."""
    x, y, a = poses[:, 0], poses[:, 1], poses[:, 2]
    vx, vy, va = velocities[:, 0] * dt, velocities[:, 1] * dt, velocities[:, 2] * dt
    cos_a, sin_a = np.cos(a), np.sin(a)
    return np.stack(
        [x + vx * cos_a - vy * sin_a, y + vx * sin_a + vy * cos_a, normalize_angle(a + normalize_angle(va))],
        axis=1,
    )
