"""Compiled (numba) body velocities, moves and odometry: :mod:`stage_sim.sim.kinematics` and
:mod:`stage_sim.sim.odometry` in one pass over the robots, with their arithmetic exactly.

Why: for one or ten robots a step is dominated by the dozens of small numpy calls of the reference, not by
arithmetic. The trigonometry stays in numpy (the caller passes the cosines and sines, computed by the same
numpy calls as the reference, which on some CPUs differ in the last bit from libm), so every pose here is the
reference's pose bit for bit (``tests/sim/test_motion_kernels.py``). Body velocities are computed one drive
at a time by each drive's own twin (:mod:`stage_sim.sim.drives`), compiled here.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numba
import numpy as np

from stage_sim.sim.drives import DRIVES, DriveGroup, DriveGroups

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}
_VELOCITY_KERNELS = {name: numba.njit(**_JIT)(drive.compiled_velocities) for name, drive in DRIVES.items()}
#: The drives :func:`drive_velocities` steps, in this order (a compiled function can call a drive's twin only by
#: name, not from the registry: a new drive is added here too, ``tests/sim/test_motion_kernels.py`` checks).
STEPPED_DRIVES = ("diff", "omni", "car")
_diff, _omni, _car = (_VELOCITY_KERNELS[name] for name in STEPPED_DRIVES)
_NO_ROWS = np.zeros(0, dtype=np.int64)


@numba.njit(inline="always", **_JIT)
def normalize(angle):
    """:func:`~stage_sim.sim.kinematics.normalize_angle` of one angle."""
    wrapped = np.remainder(angle + np.pi, 2.0 * np.pi) - np.pi  # numba ports numpy's npy_divmod
    return np.pi if wrapped == -np.pi else wrapped


def body_velocities(commands: np.ndarray, drives: Sequence[DriveGroup], wheelbases: np.ndarray, bounds: np.ndarray,
                    cos_steer: np.ndarray, sin_steer: np.ndarray, out: np.ndarray) -> None:
    """:func:`~stage_sim.sim.kinematics.body_velocity` into ``out`` (N, 3): one compiled pass per drive, then
    one clamping pass; ``cos_steer``/``sin_steer``: numpy's cos/sin of ``commands[:, 2]`` (car drives read them)."""
    for group in drives:
        _VELOCITY_KERNELS[group.drive.name](commands, group.rows, wheelbases, cos_steer, sin_steer, out)
    clamp_velocities(out, bounds)


def drive_rows(drives: DriveGroups) -> tuple[np.ndarray, ...]:
    """The robots of each of :data:`STEPPED_DRIVES` (int64 rows, empty for a drive no robot has), as
    :func:`drive_velocities` takes them."""
    rows = {group.drive.name: group.rows for group in drives}
    return tuple(rows.get(name, _NO_ROWS) for name in STEPPED_DRIVES)


@numba.njit(**_JIT)
def drive_velocities(commands, rows, wheelbases, bounds, out):
    """:func:`body_velocities` in one compiled call (a fused step's first part), ``rows`` from :func:`drive_rows`:
    the cos and sin of the steering angle are libm's, which are numpy's (``tests/sim/test_trigonometry.py``),
    worked out for the robots of the one steered drive (``car``) only."""
    n = commands.shape[0] if rows[2].size else 0  # no car: no steering to work out
    cos_steer, sin_steer = np.empty(n), np.empty(n)
    for i in rows[2]:
        cos_steer[i], sin_steer[i] = math.cos(commands[i, 2]), math.sin(commands[i, 2])
    _diff(commands, rows[0], wheelbases, cos_steer, sin_steer, out)
    _omni(commands, rows[1], wheelbases, cos_steer, sin_steer, out)
    _car(commands, rows[2], wheelbases, cos_steer, sin_steer, out)
    clamp_velocities(out, bounds)


@numba.njit(**_JIT)
def clamp_velocities(velocities, bounds):
    """Clamp (vx, vy, va) in place to ``velocity_bounds`` (N, 8), as ``np.clip`` does in the reference."""
    for i in range(velocities.shape[0]):
        velocities[i, 0] = min(max(velocities[i, 0], bounds[i, 0]), bounds[i, 1])
        velocities[i, 1] = min(max(velocities[i, 1], bounds[i, 2]), bounds[i, 3])
        velocities[i, 2] = min(max(velocities[i, 2], bounds[i, 6]), bounds[i, 7])


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


@numba.njit(**_JIT)
def place_points(points, owner, poses, cos_a, sin_a, out):
    """:func:`~stage_sim.sim.collision.place` of ``points`` (P, 2) with the poses ``poses[owner]``, into ``out``;
    ``cos_a``/``sin_a`` of ``poses[:, 2]``."""
    for k in range(points.shape[0]):
        i = owner[k]
        px, py = points[k, 0], points[k, 1]
        out[k, 0] = poses[i, 0] + cos_a[i] * px - sin_a[i] * py
        out[k, 1] = poses[i, 1] + sin_a[i] * px + cos_a[i] * py


def warm(robots: int) -> None:
    """Run every kernel once on arrays of the simulation's types, loading them from numba's cache."""
    n = max(robots, 1)
    values, flags, rows = np.zeros((n, 3)), np.zeros(n, dtype=np.bool_), np.arange(n, dtype=np.int64)
    column, out = np.ones(n), np.empty((n, 3))
    every_drive = [DriveGroup(drive, rows) for drive in DRIVES.values()]
    body_velocities(values, every_drive, column, np.zeros((n, 8)), column, column, out)
    drive_velocities(values, drive_rows(DriveGroups(every_drive)), column, np.zeros((n, 8)), out)
    integrate_estimates(values, values, np.zeros((n, 4)), 0.1, column, column, flags, values, out)
    place_points(values[:, :2].copy(), rows, values, column, column, np.empty((n, 2)))
