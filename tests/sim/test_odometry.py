"""Odometry estimates with given and drawn odom_error."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stage_sim.sim.odometry import DEFAULT_ODOM_ERROR_RANGE, draw_odom_errors, integrate_odometry, relative_pose


def test_given_error_is_used_literally() -> None:
    given = (0.03, 0.03, 0.0, math.radians(0.05))
    errors = draw_odom_errors([given], np.random.default_rng(0))
    assert errors[0] == pytest.approx(given)


def test_drawn_error_is_within_half_the_default_range_and_seeded() -> None:
    a = draw_odom_errors([None] * 50, np.random.default_rng(7))
    b = draw_odom_errors([None] * 50, np.random.default_rng(7))
    c = draw_odom_errors([None] * 50, np.random.default_rng(8))
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    assert np.all(np.abs(a) <= DEFAULT_ODOM_ERROR_RANGE / 2)
    assert np.all(a[:, 2] == 0.0)
    assert len(np.unique(a[:, 0])) == 50  # one draw per robot


def test_forward_step_scales_distance_by_one_plus_error() -> None:
    estimate = np.array([[0.0, 0.0, 0.0]])
    errors = np.array([[0.1, 0.0, 0.0, 0.0]])
    moved = integrate_odometry(estimate, np.array([[1.0, 0.0, 0.0]]), errors, 0.1)[0]
    assert moved == pytest.approx([0.11, 0.0, 0.0])


def test_rotation_scales_by_one_plus_angular_error() -> None:
    moved = integrate_odometry(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([[0, 0, 0, 0.05]]), 0.1)[0]
    assert moved == pytest.approx([0.0, 0.0, 0.105])


def test_lateral_odometry_has_the_physical_sign() -> None:
    moved = integrate_odometry(np.array([[0.0, 0.0, math.pi / 2]]), np.array([[0.0, 1.0, 0.0]]), np.zeros((1, 4)), 0.1)
    # facing +y, moving to the robot's left means moving towards −x
    assert moved[0] == pytest.approx([-0.1, 0.0, math.pi / 2])


def test_zero_error_odometry_follows_the_true_motion_in_the_odom_frame() -> None:
    from stage_sim.sim.kinematics import integrate

    start = np.array([[3.0, 4.0, 0.7]])
    truth, odom = start.copy(), relative_pose(start, start)
    for v in ([0.5, 0.0, 0.3], [0.2, 0.0, -0.8], [1.0, 0.0, 0.0]):
        velocity = np.array([v])
        truth = integrate(truth, velocity, 0.1)
        odom = integrate_odometry(odom, velocity, np.zeros((1, 4)), 0.1)
    assert odom[0] == pytest.approx(relative_pose(truth, start)[0])
