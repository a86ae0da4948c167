"""``stage_sim view`` as users run it: one URL line, a working page, the open-bind warning, clear errors."""

from __future__ import annotations

import os
import subprocess
import sys
import urllib.request
from pathlib import Path

STAGE_SIM = Path(sys.executable).with_name("stage_sim")


def run_view(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([str(STAGE_SIM), "view", *args], capture_output=True, text=True, timeout=timeout)


def test_view_prints_its_url_once_serves_the_page_and_runs_for_the_duration() -> None:
    process = subprocess.Popen(
        [str(STAGE_SIM), "view", "rooms.world", "--controller", "wander", "--speedup", "4", "--duration", "6",
         "--view-port", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = process.stdout.readline().strip()
    assert first.startswith("view: http://127.0.0.1:") and first.endswith("/")
    opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))  # loopback, whatever the environment
    with opener.open(first.removeprefix("view: "), timeout=10) as response:
        assert response.status == 200 and b"<canvas" in response.read()
    rest, errors = process.communicate(timeout=60)
    assert process.returncode == 0, errors
    assert "view: " not in rest


def test_an_open_bind_warns_unless_read_only() -> None:
    open_bind = run_view("rooms.world", "--duration", "0.1", "--view-host", "0.0.0.0", "--view-port", "0")
    assert open_bind.returncode == 0, open_bind.stderr
    assert "anyone who can reach port" in open_bind.stderr
    read_only = run_view("rooms.world", "--duration", "0.1", "--view-host", "0.0.0.0", "--view-port", "0",
                         "--view-readonly")
    assert read_only.returncode == 0 and "WARNING" not in read_only.stderr


def test_a_broken_world_is_a_clear_error(tmp_path) -> None:
    broken = tmp_path / "broken.world"
    broken.write_text("resolution 0.02\nposition( pose [1 2 0 )\n")
    result = run_view(str(broken))
    assert result.returncode == 2
    assert f"{broken}:2:" in result.stderr
    assert "Traceback" not in result.stderr
    assert "view: " not in result.stdout


def test_kernels_and_threads_reach_the_simulation(monkeypatch) -> None:
    from stage_sim.cli import main
    from stage_sim.sim import simulation

    made = []

    class Recorded(simulation.Simulation):
        def __init__(self, *args, **kwargs) -> None:
            made.append(kwargs)
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(simulation, "Simulation", Recorded)
    monkeypatch.delenv("STAGE_SIM_THREADS", raising=False)
    assert main(["view", "rooms.world", "--duration", "0.2", "--view-port", "0", "--kernels", "numpy",
                 "--threads", "2"]) == 0
    assert main(["view", "rooms.world", "--duration", "0.2", "--view-port", "0", "--speedup", "0"]) == 0
    cores = len(os.sched_getaffinity(0))
    assert [(m["kernels"], m["threads"]) for m in made] == [("numpy", 2), (None, cores)]  # unpaced: every core
