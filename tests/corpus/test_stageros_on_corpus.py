"""``stageros`` on every corpus world: it comes up (publishing) and stops cleanly on Ctrl-C, or stops at once
with exit status 2 and a file:line:col: message. Runs two worlds at a time, each on a private ROS domain of its
own, each in a memory-capped child with a wall timeout. How long it takes to come up is a figure, not a
verdict: ``benchmarks/startup.py`` measures it, for rooms.world and for hospital.world's 1000 robots (whose
middleware set-up alone, a CPU cost per pair of publisher and subscription, moves by half with this machine's
load)."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.corpus.children import LOCATED_MESSAGE, ChildRun, RunsAhead, console_script, ros_domains, run_limited
from tests.corpus.worlds_list import FAILS_TO_LOAD, World, params

READY = re.compile(r"\[stageros\]: \S+: (?P<robots>\d+) robot\(s\), interval_sim")


def _come_up_and_stop(path: Path, env: dict[str, str] | None) -> ChildRun:
    return run_limited([console_script("stageros"), "-g", str(path)], ready=READY, env=env)


@pytest.fixture(scope="module")
def runs(request: pytest.FixtureRequest) -> Iterator[RunsAhead]:
    """The worlds' stageros runs, two at a time, each on a ROS domain of its own."""
    with ros_domains() as domains:
        ahead = RunsAhead(request, "test_stageros_comes_up_and_stops_on_ctrl_c", _come_up_and_stop, domains)
        yield ahead
        ahead.close()


@pytest.mark.parametrize("world", params())
def test_stageros_comes_up_and_stops_on_ctrl_c(world: World, runs: RunsAhead) -> None:
    run = runs.result(world.id)
    assert run.returncode is not None, f"stageros still running after its wall timeout: {run.stderr[-500:]}"
    assert "Traceback" not in run.stderr, run.stderr[-2000:]
    if world.id in FAILS_TO_LOAD:
        assert run.returncode == 2
        assert run.stderr.startswith("stageros: ") and LOCATED_MESSAGE.match(run.stderr), run.stderr
        assert FAILS_TO_LOAD[world.id] in run.stderr
    else:
        assert run.returncode == 0, run.stderr[-2000:]
        assert READY.search(run.stderr)
