"""Parameters as users type them: integers for doubles are taken, a wrong type is one clear line, at start
and at run time."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from rclpy.context import Context
from rclpy.node import Node
from rclpy.parameter import Parameter

from stage_sim.ros.parameters import ParameterSpec, ParameterTypeError, declare_parameters


def specs(applied: list) -> list[ParameterSpec]:
    return [
        ParameterSpec("speedup", 1.0, "real-time factor", on_change=applied.append),
        ParameterSpec("seed", -1, "seed"),
        ParameterSpec("publish_map", False, "publish /map"),
        ParameterSpec("world_file", "", "world"),
    ]


def node_with(context: Context, **overrides) -> Node:
    return Node("typed", context=context, parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()])


def test_an_integer_for_a_double_is_a_double(ros_context: Context) -> None:
    node = node_with(ros_context, speedup=2, seed=7, publish_map=True)
    try:
        values = declare_parameters(node, specs([]))
        assert values == {"speedup": 2.0, "seed": 7, "publish_map": True, "world_file": ""}
        assert isinstance(values["speedup"], float)
    finally:
        node.destroy_node()


@pytest.mark.parametrize(("override", "message"), [
    ({"seed": 1.5}, "parameter 'seed' takes an integer, not 1.5 (float)"),
    ({"publish_map": 1}, "parameter 'publish_map' takes a boolean (true/false), not 1 (int)"),
    ({"speedup": "fast"}, "parameter 'speedup' takes a double, not 'fast' (str)"),
    ({"seed": True}, "parameter 'seed' takes an integer, not True (bool)"),
])
def test_a_wrong_type_at_start_is_one_line(ros_context: Context, override: dict, message: str) -> None:
    node = node_with(ros_context, **override)
    try:
        with pytest.raises(ParameterTypeError) as error:
            declare_parameters(node, specs([]))
        assert str(error.value) == message
    finally:
        node.destroy_node()


def test_at_run_time_a_wrong_type_is_refused_a_good_one_applied_and_start_only_ones_are_read_only(
        ros_context: Context) -> None:
    applied: list = []
    node = node_with(ros_context)
    try:
        declare_parameters(node, specs(applied))
        (result,) = node.set_parameters([Parameter("speedup", value=3)])
        assert result.successful and applied == [3.0]
        (result,) = node.set_parameters([Parameter("speedup", value="x")])
        assert not result.successful and result.reason == "parameter 'speedup' takes a double, not 'x' (str)"
        assert applied == [3.0] and node.get_parameter("speedup").value == 3
        (result,) = node.set_parameters([Parameter("seed", value=4)])
        assert not result.successful and "read-only" in result.reason
    finally:
        node.destroy_node()


def stageros(*args: str, timeout: float = 60) -> tuple[int | None, str]:
    """stageros as users start it: its exit status (None if still up) and what it printed, stopped once up."""
    process = subprocess.Popen([str(Path(sys.executable).with_name("stageros")), "-g", "rooms.world", *args],
                               stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
    lines = []
    deadline = time.monotonic() + timeout
    for line in process.stderr:
        lines.append(line)
        if "robot(s), interval_sim" in line or time.monotonic() > deadline:
            process.send_signal(signal.SIGINT)
            process.communicate(timeout=60)
            return None, "".join(lines)
    return process.wait(), "".join(lines)


def test_stageros_takes_integers_for_doubles_as_users_type_them() -> None:
    status, output = stageros("--ros-args", "-p", "speedup:=2", "-p", "base_watchdog_timeout:=1")
    assert status is None and output.rstrip().endswith("speedup 2") and "Traceback" not in output, output


@pytest.mark.parametrize(("param", "message"), [
    ("seed:=1.5", "parameter 'seed' takes an integer, not 1.5 (float)"),
    ("publish_map:=1", "parameter 'publish_map' takes a boolean (true/false), not 1 (int)"),
])
def test_stageros_refuses_a_wrong_type_in_one_line(param: str, message: str) -> None:
    status, output = stageros("--ros-args", "-p", param)
    assert status == 2 and output.strip() == f"stageros: {message}", output


def test_wander_takes_integer_lists_for_double_lists_and_refuses_a_wrong_type() -> None:
    wander = str(Path(sys.executable).with_name("wander"))
    refused = subprocess.run([wander, "--ros-args", "-p", "forward_speed:=fast"], capture_output=True, text=True,
                             timeout=60, stdin=subprocess.DEVNULL)
    assert refused.returncode == 2
    assert refused.stderr.strip() == "wander: parameter 'forward_speed' takes a double, not 'fast' (str)"
    process = subprocess.Popen([wander, "--ros-args", "-p", "forward_speed:=1", "-p", "laser_pose:=[0, 0, 1]"],
                               stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    line = process.stderr.readline()
    process.send_signal(signal.SIGINT)
    process.communicate(timeout=30)
    assert "waiting for scans" in line and process.returncode == 0, line
