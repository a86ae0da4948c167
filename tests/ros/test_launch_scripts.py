"""The launch scripts as users run them: ``python launch_scripts/<name>.py`` in a process of its own."""

from __future__ import annotations

import json
import os
import pty
import signal
import subprocess
import sys
import termios
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SCRIPTS = REPO / "launch_scripts"
KEYS = {"robot", "sim_seconds", "distance_m", "stall_events", "longest_stop_s", "coverage"}


def run_script(name: str, *args: str, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPTS / name), "-g", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=dict(os.environ))


def summaries(stdout: str) -> list[dict]:
    return [json.loads(line) for line in stdout.splitlines() if line.startswith("{")]


@pytest.mark.slow
def test_reactive_runs_60_sim_seconds_and_prints_its_summary(tmp_path: Path) -> None:
    result = run_script("reactive.py", "--duration", "60", "--speedup", "0", "--seed", "1", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    (summary,) = summaries(result.stdout)
    assert set(summary) == KEYS
    assert summary["robot"] == "robot"
    assert summary["sim_seconds"] == pytest.approx(60.0)
    assert summary["stall_events"] == 0
    assert summary["longest_stop_s"] < 2.0
    assert summary["distance_m"] > 25.0  # cruising at up to 0.7 m/s most of the time
    assert 0.03 < summary["coverage"] < 1.0  # a minute sees a few rooms of rooms.world, not all of it


@pytest.mark.slow
def test_multi_reactive_drives_every_robot_with_its_own_wanderer(tmp_path: Path) -> None:
    result = run_script("multi_reactive.py", "--duration", "20", "--speedup", "0", "--seed", "2", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    runs = summaries(result.stdout)
    assert [s["robot"] for s in runs] == ["robot", "alice", "bob", "carol"]
    for summary in runs:
        assert summary["sim_seconds"] == pytest.approx(20.0)
        assert summary["stall_events"] == 0, summary
        assert summary["longest_stop_s"] < 2.0, summary
        assert summary["distance_m"] > 5.0, summary


def test_same_seed_gives_the_same_lockstep_run(tmp_path: Path) -> None:
    first = run_script("reactive.py", "--duration", "8", "--speedup", "0", "--seed", "5", cwd=tmp_path)
    again = run_script("reactive.py", "--duration", "8", "--speedup", "0", "--seed", "5", cwd=tmp_path)
    assert first.returncode == again.returncode == 0, first.stderr + again.stderr
    assert summaries(first.stdout) == summaries(again.stdout)


def test_record_writes_one_frame_per_interval(tmp_path: Path) -> None:
    from PIL import Image

    gif = tmp_path / "wander.gif"
    result = run_script("reactive.py", "--duration", "4", "--speedup", "0", "--seed", "1", "--record", str(gif),
                        "--record-every", "1", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert f"recorded 5 frames to {gif}" in result.stderr
    with Image.open(gif) as image:
        assert image.n_frames == 4 / 1 + 1


def test_ctrl_c_still_prints_the_summaries(tmp_path: Path) -> None:
    process = subprocess.Popen([sys.executable, str(SCRIPTS / "reactive.py"), "-g", "--speedup", "2"], cwd=tmp_path,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=dict(os.environ))
    time.sleep(6.0)
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=30)
    assert process.returncode == 0, stderr
    (summary,) = summaries(stdout)
    assert summary["sim_seconds"] > 1.0 and summary["stall_events"] == 0


def test_a_session_ends_at_the_worlds_quit_time_and_runs_at_the_worlds_speedup(tmp_path: Path) -> None:
    world = tmp_path / "short.world"
    world.write_text("quit_time 3\nspeedup 0\nresolution 0.02\nposition( pose [0 0 0 0] )\n")
    result = run_script("reactive.py", str(world), "--seed", "1", cwd=tmp_path, timeout=120)
    assert result.returncode == 0, result.stderr
    (summary,) = summaries(result.stdout)
    assert summary["sim_seconds"] == pytest.approx(3.0)
    assert "(as fast as possible)" in result.stderr  # the world's speedup 0, not a default of the session's own
    shorter = run_script("reactive.py", str(world), "--duration", "1", "--seed", "1", cwd=tmp_path, timeout=120)
    assert shorter.returncode == 0, shorter.stderr
    assert summaries(shorter.stdout)[0]["sim_seconds"] == pytest.approx(1.0)


def test_a_broken_world_exits_2_naming_it(tmp_path: Path) -> None:
    broken = tmp_path / "broken.world"
    broken.write_text("resolution 0.02\nposition( pose [1 2 0 ] \n")
    for script in ("reactive.py", "multi_reactive.py"):
        result = run_script(script, str(broken), "--duration", "1", cwd=tmp_path, timeout=60)
        assert result.returncode == 2, result.stderr
        assert str(broken) in result.stderr and "Traceback" not in result.stderr


def test_teleop_session_drives_from_the_keyboard_and_restores_the_terminal(tmp_path: Path) -> None:
    from PIL import Image

    master, slave = pty.openpty()
    before = termios.tcgetattr(slave)
    png = tmp_path / "last.png"
    process = subprocess.Popen([sys.executable, str(SCRIPTS / "teleop.py"), "-g", "--speedup", "4", "--duration", "6",
                                "--record", str(png)], cwd=tmp_path, stdin=slave, stdout=slave,
                               stderr=subprocess.PIPE, text=True, env=dict(os.environ))
    try:
        output = b""
        deadline = time.monotonic() + 30
        while b"currently:" not in output and time.monotonic() < deadline:  # the teleop's status line
            output += os.read(master, 4096) if _readable(master) else b""
        assert b"currently:" in output, output
        os.write(master, b"i")
        _, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 0, stderr
    assert termios.tcgetattr(slave) == before
    with Image.open(png) as image:
        assert image.n_frames == 1
    os.close(master)
    os.close(slave)


def _readable(fd: int) -> bool:
    import select

    return bool(select.select([fd], [], [], 0.1)[0])


def test_bag_records_the_session_and_the_summaries_still_print(tmp_path: Path) -> None:
    from tests.bags.readers import read_with_rosbags

    bag = tmp_path / "wander.mcap"
    result = run_script("multi_reactive.py", "--duration", "3", "--speedup", "0", "--seed", "1", "--bag", str(bag),
                        cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert len(summaries(result.stdout)) == 4
    counts = read_with_rosbags(bag).counts()
    assert counts["/clock"] == 30
    for robot in range(4):  # every robot's scans and odometry, one message per step
        assert counts[f"/robot_{robot}/base_scan"] == counts[f"/robot_{robot}/odom"] == 30


@pytest.mark.slow
def test_a_lockstep_session_gives_what_the_core_run_of_the_sweep_gives(tmp_path: Path) -> None:
    """``wander_sweep.py --core`` stands for the ROS sessions: same seed, same summaries, to the last digit."""
    from stage_sim.runs.wander_run import wander_summaries
    from stage_sim.worldfile.loader import load_world

    result = run_script("multi_reactive.py", "--duration", "30", "--speedup", "0", "--seed", "4", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    core = wander_summaries(load_world("multi_robots.world"), 4, 30.0)
    assert summaries(result.stdout) == core
    assert all(robot["distance_m"] > 5 for robot in core)
