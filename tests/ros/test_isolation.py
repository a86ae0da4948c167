"""Runs side by side never cross-talk: launch scripts pick a private DDS domain, and a simulator that
finds another publisher of /clock on its domain says so, naming it."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from stage_sim.ros.domain import DDS_DOMAIN_GAIN, DDS_PORT_BASE, DDS_UNICAST_OFFSET, participant_listening

REPO = Path(__file__).resolve().parents[2]
REACTIVE = REPO / "launch_scripts" / "reactive.py"
STAGEROS = Path(sys.executable).with_name("stageros")
PRIVATE = re.compile(r"reactive\.py: on private ROS_DOMAIN_ID (\d+)")
SESSION_ARGS = ["--duration", "20", "--speedup", "0", "--seed", "7", "-g"]


def without_domain() -> dict[str, str]:
    """The environment of a user who never heard of ROS_DOMAIN_ID."""
    env = dict(os.environ)
    env.pop("ROS_DOMAIN_ID", None)
    return env


def start_session() -> subprocess.Popen:
    return subprocess.Popen([sys.executable, str(REACTIVE), *SESSION_ARGS], env=without_domain(), cwd=REPO,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def finish(process: subprocess.Popen) -> tuple[list[dict], int]:
    """The session's JSON summaries and the domain it announced."""
    out, err = process.communicate(timeout=240)
    assert process.returncode == 0, err[-2000:]
    announced = PRIVATE.search(err)
    assert announced is not None, err[-2000:]
    return [json.loads(line) for line in out.splitlines()], int(announced.group(1))


def test_three_lockstep_sessions_at_once_match_one_alone() -> None:
    alone, _ = finish(start_session())
    assert alone[0]["sim_seconds"] == 20.0 and alone[0]["distance_m"] > 1.0
    together = [start_session() for _ in range(3)]
    results = [finish(process) for process in together]
    assert [summaries for summaries, _ in results] == [alone] * 3
    assert len({domain for _, domain in results}) == 3


def test_a_domain_the_user_set_is_kept(capsys: pytest.CaptureFixture[str]) -> None:
    from stage_sim.ros.domain import use_private_domain

    assert use_private_domain("demo") == int(os.environ["ROS_DOMAIN_ID"])
    assert f"demo: on ROS_DOMAIN_ID {os.environ['ROS_DOMAIN_ID']} (from the environment)" in capsys.readouterr().err


def test_a_domain_with_a_dds_participant_counts_as_taken() -> None:
    domain = 99
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as participant:
        try:
            participant.bind(("", DDS_PORT_BASE + DDS_DOMAIN_GAIN * domain + DDS_UNICAST_OFFSET))
        except OSError:
            pytest.skip("a DDS participant of another program holds domain 99's port right now")
        assert participant_listening(domain)


def wait_for(path: Path, text: str, timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if text in path.read_text():
            return True
        time.sleep(0.2)
    return False


def test_second_simulator_on_one_domain_is_reported_by_name(tmp_path: Path) -> None:
    logs = [tmp_path / "first.log", tmp_path / "second.log"]
    processes = []
    try:
        for world, log in zip(["rooms.world", "corridor.world"], logs, strict=True):
            with log.open("w") as sink:
                processes.append(subprocess.Popen([str(STAGEROS), "-g", world], stdout=sink, stderr=subprocess.STDOUT))
            assert wait_for(log, "robot(s), interval_sim", 30.0), log.read_text()
        complaint = "another node named /stageros as well publishes /clock on ROS_DOMAIN_ID"
        assert wait_for(logs[1], complaint, 10.0), logs[1].read_text()
        assert wait_for(logs[0], complaint, 10.0), logs[0].read_text()
    finally:
        for process in processes:
            process.send_signal(signal.SIGINT)
        for process in processes:
            assert process.wait(timeout=20) == 0
