"""Every console script answers ``--help`` and exits, and says what it is waiting for."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

SCRIPTS = ("stage_sim", "stageros", "wander", "teleop")


@pytest.mark.parametrize("script", SCRIPTS)
def test_help_prints_usage_and_exits(script: str) -> None:
    result = subprocess.run([str(Path(sys.executable).with_name(script)), "--help"], capture_output=True, text=True,
                            timeout=60, stdin=subprocess.DEVNULL)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(f"usage: {script}"), result.stdout


def test_wander_says_which_topic_it_waits_for() -> None:
    process = subprocess.Popen(
        [str(Path(sys.executable).with_name("wander")), "--ros-args", "-r", "__ns:=/robot_3"],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        deadline = time.monotonic() + 60
        lines = []
        while time.monotonic() < deadline:
            line = process.stdout.readline()
            lines.append(line)
            if "waiting for scans" in line:
                break
        assert "waiting for scans on /robot_3/base_scan; commands go to /robot_3/cmd_vel" in lines[-1], lines
    finally:
        process.send_signal(signal.SIGINT)
        process.communicate(timeout=30)
    assert process.returncode == 0
