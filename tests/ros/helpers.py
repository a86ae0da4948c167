"""Helpers shared by the ROS tests."""

from __future__ import annotations

import time
from collections.abc import Callable

from rclpy.executors import Executor


def spin_until(
    executor: Executor, condition: Callable[[], bool], timeout_s: float = 10.0
) -> bool:
    """Spin until ``condition()`` holds or ``timeout_s`` wall seconds pass; returns the condition."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            return False
        executor.spin_once(timeout_sec=0.01)
    return True
