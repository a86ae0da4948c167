"""Floor of Stage's jumps over empty regions: the chain of one jump after another, alone, compiled.

Run with the venv's python: ``taskset -c 0 .venv/bin/python benchmarks/jump_chain.py``. Prints one JSON line
per beam slope: ns per jump of Stage's jump (the nearer crossing taken, both crossings and distances advanced,
the step count truncated: :mod:`stage_sim.sensing.traversal`'s arithmetic) with no region looked up, and of
the same without the step count, in a loop that does nothing else (the walk's own
:func:`~stage_sim.sensing.traversal.stage_jump`). Every jump depends on the one before, so this is what each
of the ~95 jumps of a beam of the 1 mm RL world (``worlds.py``) costs at the least, whatever the region
lookups around it cost: ``rl_world_jumps_ms`` is that floor for one step of that world (102,400 beams).
"""

from __future__ import annotations

import json
import time

import numba
import numpy as np

from stage_sim.sensing.traversal import stage_jump

JUMPS = 20_000_000
RL_BEAMS = 102_400
RL_JUMPS_PER_BEAM = 95  # measured on the RL world of benchmarks/worlds.py (counted in the compiled walk)
REGION = 32.0


@numba.njit
def jumps(count: int, tana: float, step_count: bool) -> float:
    """``count`` of Stage's jumps for a beam of slope ``tana``; returns a sum so nothing is optimised away."""
    xjumpx, xjumpy = REGION, REGION * tana
    yjumpx, yjumpy = REGION / tana, REGION
    xjumpdist, yjumpdist = abs(xjumpx) + abs(xjumpy), abs(yjumpx) + abs(yjumpy)
    xcrossx, xcrossy, ycrossx, ycrossy = 10.3, 7.1, 12.2, 9.9
    dist_x, dist_y = 5.5, 17.25
    steps_left = 1e15
    total = 0.0
    for _ in range(count):
        basex, basey, jumped, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y = stage_jump(
            xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, xjumpx, xjumpy, yjumpx, yjumpy, xjumpdist, yjumpdist)
        if step_count:
            steps_left = np.trunc(steps_left - jumped)
        total += basex + basey
        if not steps_left > 0:
            break
    return total + steps_left


def ns_per_jump(tana: float, step_count: bool) -> float:
    """Best of three runs of :data:`JUMPS` jumps."""
    jumps(10, tana, step_count)  # compile
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        jumps(JUMPS, tana, step_count)
        best = min(best, time.perf_counter() - start)
    return best / JUMPS * 1e9


def main() -> None:
    for tana in (0.05, 0.41, 0.9):
        stage = ns_per_jump(tana, True)
        bare = ns_per_jump(tana, False)
        per_step = RL_JUMPS_PER_BEAM * RL_BEAMS / 1e6
        print(json.dumps({"tana": tana, "ns_per_jump": round(stage, 2),
                          "ns_per_jump_without_step_count": round(bare, 2),
                          "rl_world_jumps_ms": round(stage * per_step, 1),
                          "rl_world_jumps_ms_without_step_count": round(bare * per_step, 1)}), flush=True)


if __name__ == "__main__":
    main()
