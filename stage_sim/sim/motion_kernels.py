"""Compiled (numba) body velocities, moves and odometry: :mod:`stage_sim.sim.kinematics` and
:mod:`stage_sim.sim.odometry` in one pass over the robots, with their arithmetic exactly.

Why: for one or ten robots a step is dominated by the dozens of small numpy calls of the reference, not by
arithmetic. The trigonometry stays in numpy (the caller passes the cosines and sines, computed by the same
numpy calls as the reference, which on some CPUs differ in the last bit from libm), so every pose here is the
reference's pose bit for bit (``tests/sim/test_motion_kernels.py``).
"""

from __future__ import annotations

import numba
import numpy as np

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}
_CAR = 2
_OMNI = 1


@numba.njit(inline="always", **_JIT)
def normalize(angle):
    """:func:`~stage_sim.sim.kinematics.normalize_angle` of one angle."""
    wrapped = np.remainder(angle + np.pi, 2.0 * np.pi) - np.pi  # numba ports numpy's npy_divmod
    return np.pi if wrapped == -np.pi else wrapped


@numba.njit(**_JIT)
def body_velocities(commands, drives, wheelbases, bounds, cos_steer, sin_steer, out):
    """:func:`~stage_sim.sim.kinematics.body_velocity` into ``out`` (N, 3); ``cos_steer``/``sin_steer``:
    numpy's cos/sin of ``commands[:, 2]`` (read for car drives only)."""
    for i in range(commands.shape[0]):
        gx, gy, ga = commands[i, 0], commands[i, 1], commands[i, 2]
        vx, vy, va = gx, 0.0, ga
        if drives[i] == _CAR:
            vx = gx * cos_steer[i]
            va = gx * sin_steer[i] / wheelbases[i]
        elif drives[i] == _OMNI:
            vy = gy
        out[i, 0] = min(max(vx, bounds[i, 0]), bounds[i, 1])
        out[i, 1] = min(max(vy, bounds[i, 2]), bounds[i, 3])
        out[i, 2] = min(max(va, bounds[i, 6]), bounds[i, 7])


@numba.njit(**_JIT)
def integrate_poses(poses, velocities, dt, cos_a, sin_a, out):
    """:func:`~stage_sim.sim.kinematics.integrate` into ``out``; ``cos_a``/``sin_a`` of ``poses[:, 2]``."""
    for i in range(poses.shape[0]):
        vx, vy, va = velocities[i, 0] * dt, velocities[i, 1] * dt, velocities[i, 2] * dt
        out[i, 0] = poses[i, 0] + vx * cos_a[i] - vy * sin_a[i]
        out[i, 1] = poses[i, 1] + vx * sin_a[i] + vy * cos_a[i]
        out[i, 2] = normalize(poses[i, 2] + normalize(va))


@numba.njit(**_JIT)
def integrate_estimates(estimates, velocities, errors, dt, cos_a, sin_a, uses_odom, truth, out):
    """:func:`~stage_sim.sim.odometry.integrate_odometry` for robots with ``uses_odom``, ``truth`` for the
    others (the simulation's gps localization), into ``out``; ``cos_a``/``sin_a`` of ``estimates[:, 2]``."""
    for i in range(estimates.shape[0]):
        if not uses_odom[i]:
            out[i, 0], out[i, 1], out[i, 2] = truth[i, 0], truth[i, 1], truth[i, 2]
            continue
        dx = velocities[i, 0] * dt * (1.0 + errors[i, 0])
        dy = velocities[i, 1] * dt * (1.0 + errors[i, 1])
        da = velocities[i, 2] * dt * (1.0 + errors[i, 3])
        out[i, 0] = estimates[i, 0] + dx * cos_a[i] - dy * sin_a[i]
        out[i, 1] = estimates[i, 1] + dx * sin_a[i] + dy * cos_a[i]
        out[i, 2] = normalize(estimates[i, 2] + da)


def warm(robots: int) -> None:
    """Run every kernel once on arrays of the simulation's types, loading them from numba's cache."""
    n = max(robots, 1)
    values, flags, codes = np.zeros((n, 3)), np.zeros(n, dtype=np.bool_), np.zeros(n, dtype=np.int64)
    column, out = np.zeros(n), np.empty((n, 3))
    body_velocities(values, codes, column, np.zeros((n, 8)), column, column, out)
    integrate_estimates(values, values, np.zeros((n, 4)), 0.1, column, column, flags, values, out)
