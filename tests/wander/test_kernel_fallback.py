"""Without numba the wanderer's checks run as plain Python and decide as the compiled ones do."""

from __future__ import annotations

import numpy as np

from stage_sim.wander import kernels
from tests.wander.decisions import FIXTURE, run

KERNELS = ("_body_distance", "arc_margins", "nearest_distance", "_collect", "_add_once", "mark_scan")


def test_plain_python_kernels_give_the_recorded_commands(monkeypatch):
    for name in KERNELS:
        monkeypatch.setattr(kernels, name, getattr(kernels, name).py_func)
    commands, _ = run("rooms.world", 3, 30)
    assert np.array_equal(commands, np.load(FIXTURE)["rooms.world:commands"][:30])
