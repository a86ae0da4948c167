"""``stageros`` on every corpus world: it comes up (publishing) within 10 s of CPU time (plus the
middleware's share for a world of many robots) and stops cleanly on Ctrl-C, or stops at once with exit
status 2 and a file:line:col: message. Runs on the test session's private ROS domain, one world at a time,
each in a memory-capped child."""

from __future__ import annotations

import re

import pytest

from tests.corpus.children import CPU_BUDGET_S, LOCATED_MESSAGE, console_script, run_limited
from tests.corpus.worlds_list import FAILS_TO_LOAD, World, params

READY = re.compile(r"\[stageros\]: \S+: (?P<robots>\d+) robot\(s\), interval_sim")
ENDPOINT_CPU_S = 0.001
"""The middleware's share, beyond the budget of the simulator's own work: Fast DDS creates a publisher or a
subscription in time growing with the participant's endpoints (about 1 ms each at hospital.world's 4,000:
three publishers and a subscription per robot)."""
ENDPOINTS_PER_ROBOT = 4


def cpu_budget(stderr: str) -> float:
    """The CPU seconds stageros may take to come up on the world it announced in ``stderr``."""
    ready = READY.search(stderr)
    robots = int(ready["robots"]) if ready else 0
    return CPU_BUDGET_S + ENDPOINT_CPU_S * ENDPOINTS_PER_ROBOT * robots


@pytest.mark.parametrize("world", params())
def test_stageros_comes_up_and_stops_on_ctrl_c(world: World) -> None:
    run = run_limited([console_script("stageros"), "-g", str(world.path)], ready=READY)
    assert run.returncode is not None, f"stageros still running after its wall timeout: {run.stderr[-500:]}"
    assert "Traceback" not in run.stderr, run.stderr[-2000:]
    if world.id in FAILS_TO_LOAD:
        assert run.returncode == 2
        assert run.stderr.startswith("stageros: ") and LOCATED_MESSAGE.match(run.stderr), run.stderr
        assert FAILS_TO_LOAD[world.id] in run.stderr
    else:
        assert run.returncode == 0, run.stderr[-2000:]
        assert READY.search(run.stderr)
    assert run.cpu_seconds < cpu_budget(run.stderr)
