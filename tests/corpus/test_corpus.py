"""Real Stage worlds load and step, or stop with exit status 2 and a file:line:col: message.

Every world runs in a child process with capped memory (tests/corpus/children.py); ``stage_sim inspect``
must finish within 10 s of CPU time (its runs go one at a time, so that each one's CPU time is its own; the
driver's go two at a time).
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.corpus.children import CPU_BUDGET_S, LOCATED_MESSAGE, ChildRun, RunsAhead, python_command, run_limited
from tests.corpus.worlds_list import CORPUS, FAILS_TO_LOAD, OWN_WORLDS, World, params, worlds

DRIVER = str(OWN_WORLDS.parent / "drive_world.py")


def test_the_corpus_travels_with_the_repository() -> None:
    """Stage's and stage_ros' worlds are in tests/data/corpus (a clone needs nothing beside it), every world
    expected to fail names a file that is there, and the licences of both origins are kept with them."""
    ids = {world.id for world in worlds()}
    assert sum(i.startswith("stage-worlds/") for i in ids) >= 29
    assert sum(i.startswith("stage_ros-world/") for i in ids) >= 5
    assert set(FAILS_TO_LOAD) <= ids
    assert (CORPUS / "stage-worlds" / "COPYING.txt").read_text().lstrip().startswith("GNU GENERAL PUBLIC LICENSE")
    assert "Licence" in (CORPUS / "README.md").read_text()


@pytest.mark.parametrize("world", params())
def test_inspect_loads_or_stops_with_a_located_message(world: World) -> None:
    run = run_limited(python_command("-m", "stage_sim.cli", "inspect", "--json", str(world.path)))
    assert run.returncode is not None, f"inspect still running after its wall timeout: {run.stderr[-500:]}"
    assert "Traceback" not in run.stderr, run.stderr[-2000:]
    if world.id in FAILS_TO_LOAD:
        assert run.returncode == 2
        assert run.stdout == ""
        located = LOCATED_MESSAGE.match(run.stderr)
        assert located is not None and located.group("file").endswith((".world", ".inc")), run.stderr
        assert FAILS_TO_LOAD[world.id] in run.stderr.splitlines()[0]
    else:
        assert run.returncode == 0, run.stderr[-2000:]
        report = json.loads(run.stdout)
        assert report["world"]["path"] == str(world.path)
    assert run.cpu_seconds < CPU_BUDGET_S


def _drive(path: Path, env: dict[str, str] | None) -> ChildRun:
    return run_limited(python_command(DRIVER, str(path)), env=env)


@pytest.fixture(scope="module")
def drives(request: pytest.FixtureRequest) -> Iterator[RunsAhead]:
    """The driver's runs, two at a time (no ROS in them); ``inspect``'s run alone: their CPU time is judged."""
    runs = RunsAhead(request, "test_every_robot_drives_for_ten_steps", _drive)
    yield runs
    runs.close()


@pytest.mark.parametrize("world", params(loading_only=True))
def test_every_robot_drives_for_ten_steps(world: World, drives: RunsAhead) -> None:
    run = drives.result(world.id)
    assert run.returncode == 0, run.stderr[-2000:]
    result = json.loads(run.stdout)
    assert result["steps"] == 10
    assert result["finite_poses"] and result["finite_scans"]
    assert result["neither_moved_nor_stalled"] == []
    assert result["unsupported_type_warnings"] == dict.fromkeys(result["unsupported_types"], 1)
