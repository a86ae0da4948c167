"""The core's Python log reaches the ROS logger while stageros runs, at the record's severity."""

from __future__ import annotations

import logging

from stage_sim.ros.core_log import core_log_on


class FakeRosLogger:
    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def debug(self, text: str) -> None:
        self.lines.append(("debug", text))

    def info(self, text: str) -> None:
        self.lines.append(("info", text))

    def warning(self, text: str) -> None:
        self.lines.append(("warning", text))

    def error(self, text: str) -> None:
        self.lines.append(("error", text))


def test_core_records_of_info_and_above_reach_the_ros_logger_only_inside_the_block() -> None:
    ros = FakeRosLogger()
    core = logging.getLogger("stage_sim.sim.kernel_upgrade")
    with core_log_on(ros):  # type: ignore[arg-type]
        core.debug("not shown")
        core.info("simulation kernels: %s", "numba")
        core.warning("compiled kernels unavailable")
        core.error("broken")
    core.warning("after the block")
    assert ros.lines == [
        ("info", "simulation kernels: numba"), ("warning", "compiled kernels unavailable"), ("error", "broken")]
    assert logging.getLogger("stage_sim").handlers == []
