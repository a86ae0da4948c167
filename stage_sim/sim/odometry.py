"""Odometry estimates: Stage's ``localization`` modes and its ``odom_error`` model, for many robots.

``gps`` (Stage's default): the estimate is the true pose (Stage does not apply ``localization_origin`` in
this mode). ``odom``: the estimate starts at the true pose expressed relative to the odometry origin
(``localization_origin``, else the start pose) and integrates the applied body velocity with a constant
per-robot proportional error ``e`` = (e_x, e_y, e_z, e_a)::

    a' = normalize(a + va·dt·(1 + e_a))
    dx = vx·dt·(1 + e_x),  dy = vy·dt·(1 + e_y)
    x' = x + dx·cos a − dy·sin a,  y' = y + dx·sin a + dy·cos a

A world-file ``odom_error`` is used literally (Stage 4 reads it as the error itself, the angle in world
units). When it is absent, ``e`` is drawn once uniformly in ±E/2 of Stage's defaults E = [0.03 0.03 0 0.05]
from the simulation's seeded generator. Two deliberate departures from Stage (see design.md): the lateral
term has the physical sign (Stage mirrors it), and the step uses the same start-of-step heading as the true
motion, so a zero error gives odometry equal to the truth. As in Stage the estimate keeps integrating the
commanded velocity while the robot is stalled (wheels spinning against a wall).
"""

from __future__ import annotations

import numpy as np

from stage_sim.sim.kinematics import normalize_angle

DEFAULT_ODOM_ERROR_RANGE = np.array([0.03, 0.03, 0.0, 0.05])


def draw_odom_errors(given: list[tuple[float, float, float, float] | None], rng: np.random.Generator) -> np.ndarray:
    """Per-robot errors (N, 4): the given ones verbatim, the missing ones drawn in ±E/2 (one draw per robot)."""
    errors = np.zeros((len(given), 4))
    for i, value in enumerate(given):
        if value is None:
            errors[i] = rng.uniform(-0.5, 0.5, size=4) * DEFAULT_ODOM_ERROR_RANGE
        else:
            errors[i] = value
    return errors


def relative_pose(poses: np.ndarray, origins: np.ndarray) -> np.ndarray:
    """Poses (N, 3) expressed in the frames ``origins`` (N, 3): origin⁻¹ ⊕ pose."""
    dx, dy = poses[:, 0] - origins[:, 0], poses[:, 1] - origins[:, 1]
    c, s = np.cos(origins[:, 2]), np.sin(origins[:, 2])
    return np.stack([c * dx + s * dy, -s * dx + c * dy, normalize_angle(poses[:, 2] - origins[:, 2])], axis=1)


def integrate_odometry(estimates: np.ndarray, velocities: np.ndarray, errors: np.ndarray, dt: float) -> np.ndarray:
    """Odometry estimates (N, 3) after one step of body velocities (N, 3) with errors (N, 4)."""
    a = estimates[:, 2]
    dx = velocities[:, 0] * dt * (1.0 + errors[:, 0])
    dy = velocities[:, 1] * dt * (1.0 + errors[:, 1])
    da = velocities[:, 2] * dt * (1.0 + errors[:, 3])
    c, s = np.cos(a), np.sin(a)
    return np.stack(
        [estimates[:, 0] + dx * c - dy * s, estimates[:, 1] + dx * s + dy * c, normalize_angle(a + da)], axis=1
    )
