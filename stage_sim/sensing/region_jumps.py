"""Stage's jumps over empty regions, compiled: one jump, a chain of them, and the step count they update.

Between regions holding blocks, Stage's walk (:mod:`stage_sim.sensing.stage_walk`) jumps from region to region:
to the nearer of the crossing of the next column of regions and that of the next row, each crossing advanced by
a constant and the other's distance reduced by the one jumped, in floating point. Each crossing decides where
the walk enters the next region holding a block, so the jumps are replayed one by one (~95 a beam on the 1 mm
RL world of ``benchmarks/worlds.py``, the most frequent step of a long beam at a fine resolution), in a loop
of their own that the walk (:mod:`stage_sim.sensing.traversal`) inlines: its values stay in registers.

After each jump Stage truncates its step count, ``n = (int)(n - dist)``. For a ray whose reach stays inside the
margin of the :class:`~stage_sim.sensing.stop_map.StopMap` (every ray of a world of ordinary size),
:func:`jump_through_stop_map` asks that map, a byte per region, whether a region stops it, with no bounds test,
and counts in an integer, ``n - ceil(dist)`` (:func:`steps_after_jump`: Stage's value, computed off the chain of
jumps, where the truncation of a float subtraction made each jump wait ~10 cycles for the one before:
``benchmarks/jump_chain.py``). Other rays jump through the tile grid's slots (:func:`jump_through_grid`).
"""

from __future__ import annotations

import numba
import numpy as np

from stage_sim.sensing.stage_walk import REGION_BITS

#: A jump whose distance lies above a whole number by less than ``1 - NEAR_WHOLE`` has its step count worked
#: out in floating point, as Stage does (rounding ``n - dist`` can reach the next whole number there).
NEAR_WHOLE = 1.0 - 2.0 ** -20
#: Jumps at least this long (a beam nearly along an axis: its crossing of the other axis is far) likewise.
FAR_JUMP = 2.0 ** 52
#: Step counts from which the integer count is not used (``n - dist`` rounds to 2**-21 below them).
INT_STEPS = 1 << 31

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(inline="always", **_JIT)
def stage_jump(xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, xjumpx, xjumpy, yjumpx, yjumpy, xjumpdist,
               yjumpdist):
    """Stage's jump over an empty region to the nearer of its two crossings: (the point jumped to, x and y,
    the distance jumped, then both crossings and their distances for the next jump), Stage's if/else written
    as selections (the compiler still branches on which crossing: a select chain measured slower)."""
    takex = dist_x < dist_y
    basex = xcrossx if takex else ycrossx
    basey = xcrossy if takex else ycrossy
    jumped = dist_x if takex else dist_y
    next_xx, next_xy = xcrossx + xjumpx, xcrossy + xjumpy
    next_yx, next_yy = ycrossx + yjumpx, ycrossy + yjumpy
    left_y, left_x = dist_y - dist_x, dist_x - dist_y
    return (basex, basey, jumped, next_xx if takex else xcrossx, next_xy if takex else xcrossy,
            ycrossx if takex else next_yx, ycrossy if takex else next_yy, xjumpdist if takex else left_x,
            left_y if takex else yjumpdist)


@numba.njit(**_JIT)
def jump_through_grid(basex, basey, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, steps_left, xjumpx, xjumpy,
                      yjumpx, yjumpy, xjumpdist, yjumpdist, slots, robot_regions, use_regions, rrow0, rcol0):
    """Stage's jumps from an empty region until one holding a block (static, or a robot's when
    ``use_regions``) or the end of the steps: the point jumped to, the crossings and distances, the steps.

    A loop of its own (which the compiler inlines): every value of it stays in a register, where the walk's
    loop, whose top every jump went through, shared them with everything else (5 % of a step of the 1 mm RL
    world, whose beams jump 95 times; the same time on rooms.world)."""
    rh, rw = slots.shape
    while True:
        basex, basey, jumped, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y = stage_jump(
            xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, xjumpx, xjumpy, yjumpx, yjumpy, xjumpdist,
            yjumpdist)
        steps_left = np.trunc(steps_left - jumped)
        if not steps_left > 0:
            break
        rr, rc = (int(basey) >> REGION_BITS) - rrow0, (int(basex) >> REGION_BITS) - rcol0
        if 0 <= rr < rh and 0 <= rc < rw and (slots[rr, rc] >= 0 or (use_regions and robot_regions[rr, rc] != -1)):
            break
    return basex, basey, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, steps_left


@numba.njit(inline="always", **_JIT)
def steps_after_jump(steps, jumped):
    """Stage's ``(int)(steps - jumped)`` for a step count ``0 < steps < 2**31`` (where that is not positive,
    a count that is not either).

    For an integer ``steps`` and ``jumped >= 0``, that is ``steps - ceil(jumped)``: ``steps - jumped`` lies
    strictly between two whole numbers, above ``steps - ceil(jumped)`` by ``ceil(jumped) - jumped``, and rounds
    to the one above only when that is within half a unit in the last place of it (2**-22 below 2**31); so a
    jump whose fraction lies below ``2**-20`` (or that is very long, or NaN) is done in floating point."""
    whole = np.ceil(jumped)
    if whole - jumped > NEAR_WHOLE or not whole < FAR_JUMP:
        left = np.trunc(float(steps) - jumped)
        return np.int64(left) if left > 0 else np.int64(0)
    return steps - np.int64(whole)


@numba.njit(**_JIT)
def jump_through_stop_map(basex, basey, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, steps_left, xjumpx,
                          xjumpy, yjumpx, yjumpy, xjumpdist, yjumpdist, stops, stop_row0, stop_col0):
    """:func:`jump_through_grid` for a ray whose regions all lie in the stop map (rows from region
    ``stop_row0``, columns from ``stop_col0``), with a step count below :data:`INT_STEPS`: one byte and no bounds
    test a region, the step count in an integer (the same counts, :func:`steps_after_jump`)."""
    steps = np.int64(steps_left)
    while True:
        basex, basey, jumped, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y = stage_jump(
            xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, xjumpx, xjumpy, yjumpx, yjumpy, xjumpdist,
            yjumpdist)
        steps = steps_after_jump(steps, jumped)
        if steps <= 0:
            break
        row, col = (int(basey) >> REGION_BITS) - stop_row0, (int(basex) >> REGION_BITS) - stop_col0
        if stops[np.uint64(row), np.uint64(col)]:  # unsigned: no wrap-around of negative indices to test
            break
    return basex, basey, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, float(max(steps, 0))
