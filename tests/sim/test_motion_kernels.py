"""The compiled body velocities, moves and odometry equal the numpy reference bit for bit.

Angles near ±π (where ``normalize`` wraps), exact multiples of π, zero and negative velocities, every drive,
bounds that clip, and the gps/odom localization split are all drawn.
"""

from __future__ import annotations

import numpy as np
import pytest

from stage_sim.sim import motion_kernels
from stage_sim.sim.collision import place
from stage_sim.sim.drives import DRIVES, group_by_drive
from stage_sim.sim.kinematics import body_velocity, integrate, normalize_angle
from stage_sim.sim.odometry import integrate_odometry

N = 4000


def headings(rng: np.random.Generator) -> np.ndarray:
    """Uniform headings mixed with the wrap points and their neighbours."""
    special = np.array([np.pi, -np.pi, 0.0, -0.0, np.pi / 2, np.nextafter(np.pi, 0), np.nextafter(-np.pi, 0),
                        3 * np.pi, -3 * np.pi, 2 * np.pi])
    values = rng.uniform(-4.0, 4.0, N)
    values[: special.size] = special
    return values


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_body_velocities_match_the_reference(seed):
    rng = np.random.default_rng(seed)
    commands = rng.uniform(-3, 3, (N, 3))
    commands[rng.random((N, 3)) < 0.2] = 0.0
    drives = group_by_drive(rng.choice(list(DRIVES), N))
    wheelbases = rng.uniform(0.1, 1.0, N)
    low = -rng.uniform(0, 2, (N, 4))
    bounds = np.stack([low[:, 0], -low[:, 0], low[:, 1], -low[:, 1], low[:, 2], -low[:, 2], low[:, 3], -low[:, 3]],
                      axis=1)
    out = np.empty((N, 3))
    steer = commands[:, 2]
    motion_kernels.body_velocities(commands, drives, wheelbases, bounds, np.cos(steer), np.sin(steer), out)
    assert out.tobytes() == body_velocity(commands, drives, wheelbases, bounds).tobytes()
    # the fused step's twin: every drive in one call, the steering's cos and sin its own
    fused = np.full((N, 3), np.nan)
    motion_kernels.drive_velocities(commands, motion_kernels.drive_rows(drives), wheelbases, bounds, fused)
    assert fused.tobytes() == out.tobytes()


def test_the_fused_body_velocities_step_every_drive_of_the_registry():
    """A compiled function calls each drive's twin by name: a drive added to the registry must be added there."""
    assert tuple(DRIVES) == motion_kernels.STEPPED_DRIVES
    rows = motion_kernels.drive_rows(group_by_drive(["car", "car", "diff"]))
    assert [r.tolist() for r in rows] == [[2], [], [0, 1]]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_moves_match_the_reference(seed):
    rng = np.random.default_rng(seed)
    poses = np.stack([rng.uniform(-50, 50, N), rng.uniform(-50, 50, N), headings(rng)], axis=1)
    velocities = rng.uniform(-2, 2, (N, 3)) * (rng.random((N, 1)) < 0.9)
    velocities[:20, 2] = np.pi * 10  # va·dt exactly ±π after the step
    out = np.empty_like(poses)
    motion_kernels.integrate_poses(poses, velocities, 0.1, np.cos(poses[:, 2]), np.sin(poses[:, 2]), out)
    assert out.tobytes() == integrate(poses, velocities, 0.1).tobytes()
    single = np.array([motion_kernels.normalize(a) for a in poses[:, 2]])
    assert single.tobytes() == normalize_angle(poses[:, 2]).tobytes()


@pytest.mark.parametrize("seed", [0, 1])
def test_odometry_matches_the_reference(seed):
    rng = np.random.default_rng(seed)
    estimates = np.stack([rng.uniform(-50, 50, N), rng.uniform(-50, 50, N), headings(rng)], axis=1)
    truth = rng.uniform(-50, 50, (N, 3))
    velocities = rng.uniform(-2, 2, (N, 3))
    errors = rng.uniform(-0.1, 0.1, (N, 4))
    uses_odom = rng.random(N) < 0.7
    out = np.empty_like(estimates)
    heading = estimates[:, 2]
    motion_kernels.integrate_estimates(estimates, velocities, errors, 0.1, np.cos(heading), np.sin(heading),
                                       uses_odom, truth, out)
    reference = np.where(uses_odom[:, None], integrate_odometry(estimates, velocities, errors, 0.1), truth)
    assert out.tobytes() == reference.tobytes()


@pytest.mark.parametrize("seed", [0, 1])
def test_placed_points_match_the_reference(seed):
    rng = np.random.default_rng(seed)
    poses = np.stack([rng.uniform(-50, 50, N), rng.uniform(-50, 50, N), headings(rng)], axis=1)
    points = rng.uniform(-1, 1, (N, 2))
    points[rng.random(N) < 0.2] = 0.0
    owner = rng.integers(0, N, N)
    out = np.empty((N, 2))
    motion_kernels.place_points(points, owner, poses, np.cos(poses[:, 2]), np.sin(poses[:, 2]), out)
    assert out.tobytes() == place(points, poses[owner]).tobytes()
