"""Floor of Stage's jumps over empty regions: the chain of one jump after another, alone, compiled.

Run with the venv's python: ``taskset -c 0 .venv/bin/python benchmarks/jump_chain.py``. Prints one JSON line
per beam slope: ns per jump of Stage's jump (the nearer crossing taken, both crossings and distances advanced:
:func:`~stage_sim.sensing.region_jumps.stage_jump`) in a loop that does nothing else and looks up no region, with
the step count as Stage updates it (``trunc`` of a float subtraction, each jump waiting for the one before: the
walk's count for rays beyond the stop map's margin), as the walk counts it for every other ray (an integer,
:func:`~stage_sim.sensing.region_jumps.steps_after_jump`), and with none. ``rl_world_jumps_ms*``: those figures
for one step of the 1 mm RL world (``worlds.py``: 102,400 beams, ~95 jumps each), the least its jumps cost.
"""

from __future__ import annotations

import json
import time

import numba
import numpy as np

from stage_sim.sensing.region_jumps import stage_jump, steps_after_jump

JUMPS = 20_000_000
RL_BEAMS = 102_400
RL_JUMPS_PER_BEAM = 95  # measured on the RL world of benchmarks/worlds.py (counted in the compiled walk)
REGION = 32.0
#: Step counts measured: Stage's float truncation, the walk's integer count, none.
STEP_COUNTS = ("float", "integer", "none")


@numba.njit
def jumps(count: int, tana: float, step_count: int) -> float:
    """``count`` of Stage's jumps for a beam of slope ``tana``, the step count one of :data:`STEP_COUNTS`;
    returns a sum so nothing is optimised away."""
    xjumpx, xjumpy = REGION, REGION * tana
    yjumpx, yjumpy = REGION / tana, REGION
    xjumpdist, yjumpdist = abs(xjumpx) + abs(xjumpy), abs(yjumpx) + abs(yjumpy)
    xcrossx, xcrossy, ycrossx, ycrossy = 10.3, 7.1, 12.2, 9.9
    dist_x, dist_y = 5.5, 17.25
    steps_left = 1e15
    steps = np.int64(2**31 - 1)
    total = 0.0
    for _ in range(count):
        basex, basey, jumped, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y = stage_jump(
            xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, xjumpx, xjumpy, yjumpx, yjumpy, xjumpdist, yjumpdist)
        if step_count == 0:
            steps_left = np.trunc(steps_left - jumped)
        elif step_count == 1:
            steps = steps_after_jump(steps, jumped) + 60  # kept away from 0: a count that never runs out
        total += basex + basey
        if not steps_left > 0 or steps <= 0:
            break
    return total + steps_left + steps


def ns_per_jump(tana: float, step_count: int) -> float:
    """Best of three runs of :data:`JUMPS` jumps."""
    jumps(10, tana, step_count)  # compile
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        jumps(JUMPS, tana, step_count)
        best = min(best, time.perf_counter() - start)
    return best / JUMPS * 1e9


def main() -> None:
    per_step = RL_JUMPS_PER_BEAM * RL_BEAMS / 1e6
    for tana in (0.05, 0.41, 0.9):
        stage, integer, bare = (ns_per_jump(tana, STEP_COUNTS.index(count)) for count in STEP_COUNTS)
        print(json.dumps({"tana": tana, "ns_per_jump": round(stage, 2),
                          "ns_per_jump_integer_step_count": round(integer, 2),
                          "ns_per_jump_without_step_count": round(bare, 2),
                          "rl_world_jumps_ms": round(stage * per_step, 1),
                          "rl_world_jumps_ms_integer_step_count": round(integer * per_step, 1),
                          "rl_world_jumps_ms_without_step_count": round(bare * per_step, 1)}), flush=True)


if __name__ == "__main__":
    main()
