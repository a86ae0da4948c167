"""Every benchmark script runs: each is called with tiny sizes and must exit 0 with JSON lines on stdout, so
none can rot between two `make bench` runs. Figures are not judged here (benchmarks prove speed, tests do
not); the stress script's identity and completeness checks are, as they are guarantees, not speeds."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BENCHMARKS = REPO / "benchmarks"
CHROMIUM = Path("/usr/bin/chromium")

TINY = {
    # One overhead case: the others run the same code on other worlds and controllers, a few process starts each.
    "bags": ["--duration", "5", "--cases", "straight", "--repeat", "1", "--robots", "1", "--throughput-duration", "2"],
    "envs": ["--seconds", "0.3", "--episodes", "0", "--worlds", "4"],
    "fidelity": ["--variants", "B", "--robot-worlds", "crowd_100", "--robot-seconds", "1"],
    "jump_chain": [],
    "raycast": ["--poses", "4", "--robots", "20", "--repeats", "1"],
    # The stage_sim rows only: the peers' venvs (make bench-peers) need not be there.
    "rl_peers": ["--robots", "1", "2", "--seconds", "0.1", "--reps", "1", "--cases", "stage_sim env",
                 "stage_sim env, fixed boxes", "stage_sim vector env", "stage_sim vector env, fixed boxes",
                 "stage_sim core", "stage_sim rays"],
    "simulate": ["--robots", "1", "2", "--seconds", "0.5"],
    "stageros": ["--seconds", "1"],
    # No numba compile (a cold cache takes half a minute) and no 1000-robot world (the corpus tests start it).
    "startup": ["--runs", "1", "--cases", "numpy kernels"],
    "stress": ["--quick", "--checks", "frozen", "complete", "kill9"],
    "view": ["--seconds", "1", "--cases", "cpu"],
    "wander_speed": ["--steps", "20"],
    "wander_sweep": ["--core", "--seeds", "1", "--minutes", "0.2", "--jobs", "1"],
    "worlds": ["--worlds", "floorplan", "rl", "--seconds", "0.1"],
}


def test_every_script_has_its_tiny_run() -> None:
    assert {path.stem for path in BENCHMARKS.glob("*.py")} == set(TINY)


@pytest.mark.parametrize("script", sorted(TINY))
def test_the_script_runs_and_prints_json_lines(script: str) -> None:
    if script == "view" and not CHROMIUM.exists():
        pytest.skip(f"benchmarks/view.py drives Chromium: no Chromium at {CHROMIUM} (.ci/run installs it)")
    result = subprocess.run([sys.executable, str(BENCHMARKS / f"{script}.py"), *TINY[script]], cwd=REPO,
                            capture_output=True, text=True, timeout=600, stdin=subprocess.DEVNULL)
    rows = [json.loads(line) for line in result.stdout.splitlines() if line.startswith("{")]
    assert rows and "Traceback" not in result.stderr, result.stderr[-3000:]
    # The sweep's exit status is its verdict on the wanderer (1: a seed fell short of its rule, as runs of a few
    # sim seconds do), not a failure to run.
    verdict = script == "wander_sweep" and result.returncode == 1 and rows[-1]["seeds_short"]
    assert result.returncode == 0 or verdict, result.stderr[-3000:]
    if script == "stress":
        assert [row["check"] for row in rows] == ["frozen", "complete", "kill9"]
        assert all(row["ok"] for row in rows), rows
