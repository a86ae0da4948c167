"""Stage's velocity-control kinematics, checked against hand-computed steps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stage_sim.sim.drives import group_by_drive
from stage_sim.sim.kinematics import body_velocity, integrate, normalize_angle

DEFAULT_BOUNDS = np.array([[-1, 1, -1, 1, -1, 1, -math.pi / 2, math.pi / 2]], dtype=float)


def velocity(command, drive, wheelbase=1.0, bounds=DEFAULT_BOUNDS):
    return body_velocity(np.array([command], float), group_by_drive([drive]), np.array([wheelbase]), bounds)[0]


def test_diff_ignores_lateral_command() -> None:
    assert velocity((0.5, 0.3, 0.2), "diff") == pytest.approx([0.5, 0.0, 0.2])


def test_omni_keeps_all_three_components() -> None:
    assert velocity((0.5, 0.3, 0.2), "omni") == pytest.approx([0.5, 0.3, 0.2])


def test_car_uses_angular_as_steering_angle() -> None:
    # speed 0.8 m/s, steering 0.3 rad, wheelbase 0.5 m: vx = 0.8 cos 0.3, va = 0.8 sin 0.3 / 0.5
    assert velocity((0.8, 0.0, 0.3), "car", wheelbase=0.5) == pytest.approx(
        [0.8 * math.cos(0.3), 0.0, 0.8 * math.sin(0.3) / 0.5])


def test_each_component_is_clamped_to_velocity_bounds() -> None:
    assert velocity((3.0, -2.0, 5.0), "omni") == pytest.approx([1.0, -1.0, math.pi / 2])
    bounds = np.array([[-0.2, 0.5, -0.1, 0.1, 0, 0, -0.3, 0.4]], dtype=float)
    assert velocity((-1.0, 0.5, -1.0), "omni", bounds=bounds) == pytest.approx([-0.2, 0.1, -0.3])


def test_euler_step_uses_heading_at_start_of_step() -> None:
    pose = np.array([[1.0, 2.0, math.pi / 2]])
    moved = integrate(pose, np.array([[0.5, 0.0, 1.0]]), 0.1)[0]
    # heading pi/2 at the start: 0.05 m straight along +y, then the yaw turns by 0.1 rad
    assert moved == pytest.approx([1.0, 2.05, math.pi / 2 + 0.1])


def test_omni_lateral_motion_is_to_the_left_of_the_heading() -> None:
    moved = integrate(np.array([[0.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]), 0.1)[0]
    assert moved == pytest.approx([0.0, 0.1, 0.0])


def test_yaw_wraps_into_minus_pi_pi() -> None:
    moved = integrate(np.array([[0.0, 0.0, 3.1]]), np.array([[0.0, 0.0, 1.0]]), 0.1)[0]
    assert moved[2] == pytest.approx(3.2 - 2 * math.pi)
    assert normalize_angle(-math.pi) == pytest.approx(math.pi)
