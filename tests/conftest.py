"""Session-wide test environment: loopback-only DDS discovery and a private ROS_DOMAIN_ID.

Runs before any test module imports rclpy, so every node (and every subprocess, which inherits the
environment) stays on this machine and on a domain no parallel test run is using. Nothing here imports
rclpy: the core tests must run without ROS.
"""

from __future__ import annotations

import contextlib
import os

import pytest

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

_domain_reservation: contextlib.AbstractContextManager | None = None


def pytest_configure(config: pytest.Config) -> None:
    """Reserve a free ROS_DOMAIN_ID for this run unless the caller already chose one."""
    global _domain_reservation
    if "ROS_DOMAIN_ID" in os.environ:
        return
    try:
        from domain_coordinator import domain_id
    except ImportError:  # a ROS install without domain_coordinator: fall back to the process id
        os.environ["ROS_DOMAIN_ID"] = str(1 + os.getpid() % 100)
        return
    _domain_reservation = domain_id()
    os.environ["ROS_DOMAIN_ID"] = str(_domain_reservation.__enter__())


def pytest_unconfigure(config: pytest.Config) -> None:
    """Release the reserved domain so a later run can take it."""
    global _domain_reservation
    if _domain_reservation is not None:
        _domain_reservation.__exit__(None, None, None)
        _domain_reservation = None
