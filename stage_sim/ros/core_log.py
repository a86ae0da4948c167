"""The simulation core's Python log (logger ``stage_sim``) on a ROS logger.

The core stays free of rclpy and logs with :mod:`logging`; without a handler its INFO lines (which kernels
run, when compiled ones were adopted) would be lost and its warnings would bypass ``--ros-args --log-level``.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager

from rclpy.impl.rcutils_logger import RcutilsLogger

CORE_LOGGER = "stage_sim"


class _ToRos(logging.Handler):
    """Hands each record to the ROS logger at the matching severity."""

    def __init__(self, ros_logger: RcutilsLogger) -> None:
        super().__init__()
        self.ros_logger = ros_logger

    def emit(self, record: logging.LogRecord) -> None:
        text = self.format(record)
        if record.levelno >= logging.ERROR:
            self.ros_logger.error(text)
        elif record.levelno >= logging.WARNING:
            self.ros_logger.warning(text)
        elif record.levelno >= logging.INFO:
            self.ros_logger.info(text)
        else:
            self.ros_logger.debug(text)


@contextmanager
def core_log_on(ros_logger: RcutilsLogger) -> Iterator[None]:
    """Forward the core's records of INFO and above to ``ros_logger`` while the block runs."""
    core = logging.getLogger(CORE_LOGGER)
    handler = _ToRos(ros_logger)
    level, propagate = core.level, core.propagate
    core.addHandler(handler)
    core.setLevel(logging.INFO)
    core.propagate = False  # the ROS logger prints it; the root logger's last resort would print it twice
    try:
        yield
    finally:
        core.removeHandler(handler)
        core.setLevel(level)
        core.propagate = propagate
