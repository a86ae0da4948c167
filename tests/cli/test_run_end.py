"""Where ``stage_sim run`` and ``stage_sim view`` end, as every entry point does: at the earlier of the world's
``quit_time`` and ``--duration`` (neither: Ctrl-C). ``stageros`` and the launch scripts: tests/ros."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from stage_sim.cli import main
from stage_sim.sim import simulation

STAGE_SIM = Path(sys.executable).with_name("stage_sim")


def world_file(folder: Path, quit_time: float) -> Path:
    """One robot in an empty world that runs as fast as possible by its own ``speedup``."""
    path = folder / "short.world"
    path.write_text(f"quit_time {quit_time:g}\nspeedup 0\nresolution 0.02\nposition( pose [0 0 0 0] )\n")
    return path


def stage_sim_run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(STAGE_SIM), "run", *args], capture_output=True, text=True, timeout=120)


def test_run_without_duration_ends_at_the_worlds_quit_time(tmp_path) -> None:
    result = stage_sim_run(str(world_file(tmp_path, 2.0)))
    assert result.returncode == 0, result.stderr
    assert "short.world: 2 s of sim time" in result.stdout


def test_run_ends_at_the_earlier_of_duration_and_quit_time(tmp_path) -> None:
    world = str(world_file(tmp_path, 2.0))
    assert "short.world: 1 s of sim time" in stage_sim_run(world, "--duration", "1").stdout
    assert "short.world: 2 s of sim time" in stage_sim_run(world, "--duration", "5").stdout


def test_run_help_says_how_the_run_ends() -> None:
    text = " ".join(stage_sim_run("--help").stdout.split())
    assert "until --duration sim seconds or its quit_time, whichever comes first" in text
    assert "default: the world's quit_time, else until Ctrl-C" in text


@pytest.mark.parametrize(("duration", "end"), [([], 1.5), (["--duration", "0.5"], 0.5)])
def test_view_ends_at_the_worlds_quit_time_or_the_duration(tmp_path, monkeypatch, duration, end) -> None:
    made: list[simulation.Simulation] = []

    class Recorded(simulation.Simulation):
        def __init__(self, *args, **kwargs) -> None:
            super().__init__(*args, **kwargs)
            made.append(self)

    monkeypatch.setattr(simulation, "Simulation", Recorded)
    assert main(["view", str(world_file(tmp_path, 1.5)), "--view-port", "0", *duration]) == 0
    assert made[0].sim_time == pytest.approx(end)
