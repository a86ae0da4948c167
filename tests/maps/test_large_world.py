"""A world far too large for a dense grid loads, senses and moves in bounded memory (issue #14, sparse world).

1 km × 1 km at 0.01 m is 10^10 cells: one dense bool layer would take 10 GB. The world runs in a child
process (its peak RSS is its own) whose address space is capped, so a dense array fails it at once.
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
from pathlib import Path

import pytest

CHILD = Path(__file__).with_name("large_world_child.py")
REPO = Path(__file__).resolve().parents[2]
#: numba's import alone is ~150 MB; the region indexes of a 10^10-cell world 2 × 39 MB.
RSS_CAP_MB = 600
ADDRESS_SPACE_CAP = 4 * 1024**3


def _cap() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE_CAP, ADDRESS_SPACE_CAP))


@pytest.fixture(scope="module")
def report() -> dict:
    run = subprocess.run([sys.executable, str(CHILD)], capture_output=True, text=True, timeout=300, cwd=REPO,
                         preexec_fn=_cap)
    assert run.returncode == 0, run.stderr[-2000:]
    return json.loads(run.stdout)


def test_a_kilometre_world_at_a_centimetre_loads_within_the_memory_cap(report: dict) -> None:
    height, width = report["cells"]
    assert height * width >= 10**10
    assert report["peak_rss_mb"] <= RSS_CAP_MB


def test_robots_far_apart_in_it_see_each_other_and_the_walls_and_move(report: dict) -> None:
    east_looker, north_looker, corner, far_corner = report["centre_ranges"]
    # the laser at x = 500.1 looks at the other robot's body, 0.15 m each side of x = 501: Stage's walk
    # reports whole cells from the laser's cell (500.10) to the first covered one (500.85)
    assert east_looker == pytest.approx(0.75, abs=1e-6)
    assert north_looker == pytest.approx(0.9, abs=1e-6)  # the box's south face at y = 501, laser at 500.1
    assert corner == far_corner == pytest.approx(5.0)  # nothing within range ahead: exactly range_max
    assert report["corner_moved"] == pytest.approx(0.5 * 0.5 * 2**-0.5, abs=1e-9)
    assert report["stalled"] == [False] * 4
