"""Stage's velocity-control kinematics for many robots at once, whatever their drives.

Per step of length ``dt`` (Stage's ``Move``), with the heading ``a`` at the start of the step::

    x' = x + vx·dt·cos a − vy·dt·sin a
    y' = y + vx·dt·sin a + vy·dt·cos a
    a' = normalize(a + normalize(va·dt))

The body velocity (vx, vy, va) comes from the command (gx, gy, ga) by the robot's drive model
(:mod:`stage_sim.sim.drives`); each component is then clamped to the robot's ``velocity_bounds``. There is no
acceleration limit in velocity mode (Stage's behaviour).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stage_sim.sim.drives import DriveGroup


def normalize_angle(angle: np.ndarray | float) -> np.ndarray:
    """Wrap angles to (−π, π], as Stage's ``normalize`` does."""
    wrapped = np.mod(np.asarray(angle, dtype=np.float64) + np.pi, 2.0 * np.pi) - np.pi
    return np.where(wrapped == -np.pi, np.pi, wrapped)


def true_velocities(velocities: np.ndarray, stalled: np.ndarray) -> np.ndarray:
    """The body-frame twist of each robot's true motion: its velocity, zero while stalled (the command stands,
    the body does not move). One step's (N, 3) with (N,) flags, or many steps' stacked. A copy with the stalled
    rows zeroed: the same values as ``np.where``, in a third of its time."""
    moving = velocities.copy()
    moving[stalled] = 0.0
    return moving


def body_velocity(
    commands: np.ndarray, drives: Sequence[DriveGroup], wheelbases: np.ndarray, bounds: np.ndarray
) -> np.ndarray:
    """Body-frame velocities (vx, vy, va) that Stage applies for commands (gx, gy, ga).

    ``commands`` is (N, 3), ``drives`` the robots of each drive (every robot in one group, see
    :func:`~stage_sim.sim.drives.group_by_drive`), ``wheelbases`` (N,) and ``bounds`` (N, 8)
    ``velocity_bounds`` (xmin xmax ymin ymax zmin zmax amin amax) in SI units.
    """
    velocity = np.empty_like(commands)
    for group in drives:
        velocity[group.rows] = group.drive.velocities(commands[group.rows], wheelbases[group.rows])
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
