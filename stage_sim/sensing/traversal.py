"""Compiled (numba) Stage ray walk: the same answers as :mod:`stage_sim.sensing.raycast`, bit for bit.

One ray at a time, Stage's walk as :mod:`stage_sim.sensing.stage_walk` states it (why Stage's and not the
true ray's: see there), statement for statement where it decides anything: the region test, the region
jumps with their crossings, the error term, the step count, the reported distance. A cell covered by a
robot other than the ray's own is a hit on that robot, before the static map is looked at.

The world is read through bit rows: per tile of a region, a 32-bit mask per row and per column of the cells
that stop rays (static cells at this height, :mod:`stage_sim.maps.tiles`; robot cells of this step,
:class:`~stage_sim.sensing.robot_layer.RobotLayer`). Inside a region holding blocks, the walk is Cohen's
integer line, which moves along its major axis in runs: an x-major line takes ``r`` x-steps, then one
y-step, where the first run follows from the error term and every later one is ``q`` or ``q + 1`` (``q,
rem = divmod(2·ax, 2·ay)``: ``q + 1`` when the error before the y-step is below ``rem``). So the walk takes a
whole run of cells in one test of a row mask (a column mask for y-major lines); in a run that holds set
bits it looks at those cells only, in the walk's order (a hit, or the ray's own robot, which it passes).
The error term, the step count and the steps along each axis after a run are those of the step-by-step
walk, so where the walk stops, and what it reports, are too.

Runs through empty lines of a tile are taken many at a time. Each tile keeps which of its rows and which of its
columns hold a cell, static or robot (a tile whose robot cells are all the ray's own robot's counts its static
cells only: those robot cells never stop the ray, which leaves its body through such tiles). When the rows ahead of
an x-major walk are empty (or the columns ahead, every row to the tile's edge being then free), the walk takes the
``j`` whole runs that stay inside that empty band and inside the tile, in closed form: the run ending in the
``m``-th y-step ends after ``ceil(((m − 1)·bx − e) / by)`` x-steps, ``e`` the error term before them, and the count
of runs that end within ``L`` x-steps is ``floor((L·by + e) / bx) + 1`` (y-major walks: the same with the axes
swapped). The error term, the position and the step count after them are those of the step-by-step walk, which
never looked at a set cell there. On rooms.world's scans a ray walks 2.2 runs and 1.1 such bands instead of 11.4
runs; on the 1 mm RL world of ``benchmarks/worlds.py``, whose beams leave their robot's body, 5.6 loops of runs or
bands instead of 20.9 when tiles holding robot cells were walked run by run.

Between regions, the walk replays Stage's jumps over empty regions one by one
(:mod:`stage_sim.sensing.region_jumps`: each floating-point crossing decides where it enters the next region
holding a block). The loop over rays holds the whole walk: a per-ray function taking the arrays had numba count
references to each of them, 14 atomic operations per ray (about 60 ns, more than a short ray's walk; the jump
loops, inlined, count none).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba.cpython.unsafe.numbers import leading_zeros, trailing_zeros

from stage_sim.sensing.region_jumps import INT_STEPS, jump_through_grid, jump_through_stop_map
from stage_sim.sensing.stage_walk import REGION, REGION_BITS, ZERO_ANGLE
from stage_sim.sensing.stop_map import mark_robot_regions

#: Run length standing for "no end" (a line along an axis has a single run).
_ENDLESS = 1 << 40
#: Rays per work item of the parallel loop.
_CHUNK = 64
_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(**_JIT)
def tile_masks(rows, cols, rows_used, cols_used):
    """From each tile's row masks ``rows`` (T, 32) (bit x of row y: cell (y, x)): its column masks into ``cols``
    (bit y of column x) and which rows and which columns hold a cell into ``rows_used`` and ``cols_used`` (T,)
    (bit y, bit x): the tables the walk reads, built once per static layer."""
    for t in range(rows.shape[0]):
        used_rows = np.uint32(0)
        for y in range(32):
            if rows[t, y] != 0:
                used_rows |= np.uint32(1) << np.uint32(y)
        used_cols = np.uint32(0)
        for x in range(32):
            column = np.uint32(0)
            for y in range(32):
                column |= ((rows[t, y] >> np.uint32(x)) & np.uint32(1)) << np.uint32(y)
            cols[t, x] = column
            if column != 0:
                used_cols |= np.uint32(1) << np.uint32(x)
        rows_used[t], cols_used[t] = used_rows, used_cols


@numba.njit(inline="always", **_JIT)
def _distance(ax, ay, globx, globy, startx, starty, cosa, sina, ppm):
    """Stage's reported range: the distance travelled along the major axis, in metres."""
    if ax > ay:
        return abs((globx - startx) / cosa) / ppm
    return abs((globy - starty) / sina) / ppm


@numba.njit(inline="always", **_JIT)
def _window(mask, first, length, step):
    """The bits of ``length`` cells of a 32-bit row (column) mask from cell ``first`` on, towards ``step``."""
    low = first if step > 0 else first - length + 1
    return (np.uint64(mask) >> np.uint64(low)) & ((np.uint64(1) << np.uint64(length)) - np.uint64(1))


@numba.njit(inline="always", **_JIT)
def _first(bits, length, step):
    """(steps from the window's first cell to its first set cell along the walk, ``bits`` without it)."""
    if step > 0:
        return np.int64(trailing_zeros(bits)), bits & (bits - np.uint64(1))
    high = np.int64(63 - leading_zeros(bits))
    return length - 1 - high, bits ^ (np.uint64(1) << np.uint64(high))


@numba.njit(inline="always", **_JIT)
def _quot(a, b):
    """``a // b`` for ``a >= 0``, ``b > 0``: an unsigned division, without the sign fix-ups of floor division."""
    return np.int64(np.uint64(a) // np.uint64(b))


@numba.njit(inline="always", **_JIT)
def _free_lines(used, first, step):
    """How many lines (rows or columns) of a tile from line ``first`` on, towards ``step``, have no cell,
    ``used`` holding a bit per line that has one."""
    if step > 0:
        ahead = used >> first
        return REGION - first if ahead == 0 else np.int64(trailing_zeros(ahead))
    behind = used & ((np.int64(2) << first) - 1)
    return first + 1 if behind == 0 else first - (63 - np.int64(leading_zeros(behind)))


@numba.njit(**_JIT)
def _cast_range(world, robots, flags, place, stops, pad, origins, origin_of, heading, local, jitter, trig, rmax, ppm,
                owner, out_at, out, cell, rid, a, b):
    """Rays a..b-1, ray i from point ``origins[origin_of[i]]`` at angle ``heading[origin_of[i]] + local[i]``
    (``+ jitter[out_at[i]]`` if given): range in metres (exactly ``rmax`` on a miss) into ``out[out_at[i]]``,
    flat cell hit (or -1) into ``cell[i]``, robot hit (or -1) into ``rid[i]``."""
    static_rows, static_cols, tile_of_slot, slots, rows_used, cols_used = world
    robot_regions, robot_ids, robot_rows, robot_cols, robot_rows_used, robot_cols_used, robot_owner = robots
    use_regions, use_robots = flags[0], flags[1]
    col0, row0, rcol0, rrow0, width = place[0], place[1], place[2], place[3], place[4]
    rh, rw = slots.shape
    stop_row0, stop_col0 = rrow0 - pad, rcol0 - pad
    sh, sw = stops.shape
    last_angle, last_cos, last_sin = trig
    jittered, remembered = jitter.size > 0, last_angle.size > 0
    last_origin, room_steps = -1, 0
    for i in range(a, b):
        o, at = origin_of[i], out_at[i]
        angle = heading[o] + local[i]
        if jittered:
            angle += jitter[at]
        if remembered and angle == last_angle[at]:  # a robot that did not turn: its beams' cos and sin
            cos_i, sin_i = last_cos[at], last_sin[at]
        else:  # the C library's cos and sin, as Stage's (stage_walk.beam_cos_sin)
            turned = angle if angle != 0.0 else ZERO_ANGLE
            cos_i, sin_i = math.cos(turned), math.sin(turned)
            if remembered:
                last_angle[at], last_cos[at], last_sin[at] = angle, cos_i, sin_i
        reach = ppm * rmax[i]  # the arithmetic of stage_walk.WalkRays, operation for operation
        startx, starty = origins[o, 0] * ppm, origins[o, 1] * ppm
        tana = sin_i / cos_i
        dx, dy = reach * cos_i, reach * sin_i
        own = owner[i]
        hit_range, hit_cell, hit_robot = math.inf, -1, -1
        sx = 1 if dx > 0 else (-1 if dx < 0 else 0)
        sy = 1 if dy > 0 else (-1 if dy < 0 else 0)
        ax = np.int64(abs(dx))
        ay = np.int64(abs(dy))
        bx, by = 2 * ax, 2 * ay
        exy = ay - ax
        n = ax + ay
        xmajor = ax > ay
        run_q = run_rem = 0  # every run after the first is run_q or run_q + 1 steps
        if xmajor and by > 0:
            run_q = _quot(bx, by)
            run_rem = bx - run_q * by
        elif not xmajor and bx > 0:
            run_q = _quot(by, bx)
            run_rem = by - run_q * bx
        xjumpx, xjumpy = float(sx * REGION), (sx * REGION) * tana
        yjumpx, yjumpy = (sy * REGION) / tana, float(sy * REGION)
        xjumpdist = abs(xjumpx) + abs(xjumpy)
        yjumpdist = abs(yjumpx) + abs(yjumpy)
        xcrossx = xcrossy = ycrossx = ycrossy = dist_x = dist_y = 0.0
        basex, basey = startx, starty  # globx = basex + kx: whole steps since the start or the last jump
        kx = ky = 0
        calculate_crossings = True
        if o != last_origin:  # steps a ray of this origin may take and find every region it looks at in the
            last_origin = o  # stop map: its walk looks at most (n >> REGION_BITS) + 3 regions away either way
            pr, pc = (int(starty) >> REGION_BITS) - stop_row0, (int(startx) >> REGION_BITS) - stop_col0
            room = min(pr, sh - 1 - pr, pc, sw - 1 - pc) - 3
            room_steps = min(room << REGION_BITS, INT_STEPS) if room > 0 else 0
        padded = n < room_steps
        steps_left = float(n)  # the step count as Stage's jumps update it: (int)(n - dist), kept in a float
        while steps_left > 0:
            globx, globy = basex + kx, basey + ky
            ix, iy = int(globx), int(globy)  # C's truncation, as Stage's GETREG gets it
            rr, rc = (iy >> REGION_BITS) - rrow0, (ix >> REGION_BITS) - rcol0
            slot = rtile = -1
            if 0 <= rr < rh and 0 <= rc < rw:
                slot = slots[rr, rc]
                if use_regions:
                    rtile = robot_regions[rr, rc]
            if slot >= 0 or rtile != -1:
                calculate_crossings = True
                stile = tile_of_slot[slot] if slot >= 0 else -1  # -1: nothing static at this height here
                row_used = np.int64(rows_used[stile]) if stile >= 0 else np.int64(0)
                col_used = np.int64(cols_used[stile]) if stile >= 0 else np.int64(0)
                rt = rtile if use_robots else -1  # < 0: no robot cell this layer sees here
                if rt >= 0:
                    if robot_owner[rt] == own:  # only the ray's own robot here, whose cells never stop it
                        rt = -1
                    else:
                        row_used |= np.int64(robot_rows_used[rt])
                        col_used |= np.int64(robot_cols_used[rt])
                cx0, cy0 = ix & (REGION - 1), iy & (REGION - 1)
                cx, cy = cx0, cy0
                found = False
                n = np.int64(steps_left)
                if xmajor:
                    r = -1  # x-steps before the next y-step, worked out when first needed (a skip needs none)
                    while True:
                        if by > 0:  # whole runs through an empty band of rows, or of columns
                            k = _free_lines(row_used, cy, sy)
                            if k >= 2:  # k empty rows, to the tile's last column
                                last = REGION - 1 - cx if sx > 0 else cx
                            else:  # every row to the tile's edge, in the empty columns ahead
                                k = REGION - cy if sy > 0 else cy + 1
                                last = _free_lines(col_used, cx, sx) - 1
                            room = by * last + exy  # x-steps allowed: up to ``last`` (runs are whole)
                            if room >= 0:
                                j = min(k, _quot(room, bx) + 1)  # runs that fit
                                along = _quot((j - 1) * bx - exy + by - 1, by)  # x-steps of those j runs
                                if j >= 2 and along + j <= n:
                                    cx += along * sx
                                    cy += j * sy
                                    exy += along * by - j * bx
                                    n -= along + j
                                    r = run_q + (1 if exy + bx < run_rem else 0)
                                    if n <= 0 or cy < 0 or cy >= REGION:
                                        break
                                    continue
                        if r < 0:
                            r = _quot(by - 1 - exy, by) if by > 0 else _ENDLESS
                        length = min(r + 1, n, REGION - cx if sx > 0 else cx + 1)  # cells to look at in row
                        mask = np.uint32(0)
                        if stile >= 0:
                            mask = static_rows[stile, cy]
                        if rt >= 0:
                            mask |= robot_rows[rt, cy]
                        bits = _window(mask, cx, length, sx)
                        while bits != 0:  # its set cells in the walk's order: a hit, or the ray's own robot
                            c, bits = _first(bits, length, sx)
                            x = cx + c * sx
                            if rt >= 0 and (robot_rows[rt, cy] >> x) & 1 and robot_ids[rt, cy, x] != own:
                                hit_robot, found = robot_ids[rt, cy, x], True
                            elif stile >= 0 and (static_rows[stile, cy] >> x) & 1:
                                found = True
                            if found:
                                cx = x
                                exy += c * by
                                break
                        if found:
                            break
                        if length == r + 1:  # the whole run, then the y-step
                            cx += r * sx
                            error = exy + r * by
                            exy = error - bx
                            cy += sy
                            n -= length
                            r = run_q + (1 if error < run_rem else 0)
                            if n <= 0 or cy < 0 or cy >= REGION:
                                break
                        else:  # the walk ends, or leaves the region, within the run
                            cx += length * sx
                            exy += length * by
                            n -= length
                            break
                else:
                    r = -1  # y-steps before the next x-step, likewise
                    while True:
                        if bx > 0 and exy >= 0:  # likewise, columns or rows
                            k = _free_lines(col_used, cx, sx)
                            if k >= 2:
                                last = REGION - 1 - cy if sy > 0 else cy
                            else:
                                k = REGION - cx if sx > 0 else cx + 1
                                last = _free_lines(row_used, cy, sy) - 1
                            room = bx * last - exy - 1
                            if room >= 0:
                                j = min(k, _quot(room, by) + 1)
                                along = _quot(exy + (j - 1) * by, bx) + 1
                                if j >= 2 and along + j <= n:
                                    cy += along * sy
                                    cx += j * sx
                                    exy += j * by - along * bx
                                    n -= along + j
                                    r = run_q + (1 if exy - by + run_rem >= 0 else 0)
                                    if n <= 0 or cx < 0 or cx >= REGION:
                                        break
                                    continue
                        if r < 0:
                            r = 0 if exy < 0 else (_quot(exy, bx) + 1 if bx > 0 else _ENDLESS)
                        length = min(r + 1, n, REGION - cy if sy > 0 else cy + 1)
                        mask = np.uint32(0)
                        if stile >= 0:
                            mask = static_cols[stile, cx]
                        if rt >= 0:
                            mask |= robot_cols[rt, cx]
                        bits = _window(mask, cy, length, sy)
                        while bits != 0:
                            c, bits = _first(bits, length, sy)
                            y = cy + c * sy
                            if rt >= 0 and (robot_cols[rt, cx] >> y) & 1 and robot_ids[rt, y, cx] != own:
                                hit_robot, found = robot_ids[rt, y, cx], True
                            elif stile >= 0 and (static_cols[stile, cx] >> y) & 1:
                                found = True
                            if found:
                                cy = y
                                exy -= c * bx
                                break
                        if found:
                            break
                        if length == r + 1:  # the whole run, then the x-step
                            cy += r * sy
                            error = exy - r * bx
                            exy = error + by
                            cx += sx
                            n -= length
                            r = run_q + (1 if error + run_rem >= 0 else 0)
                            if n <= 0 or cx < 0 or cx >= REGION:
                                break
                        else:
                            cy += length * sy
                            exy -= length * bx
                            n -= length
                            break
                kx += cx - cx0
                ky += cy - cy0
                steps_left = float(n)
                if found:
                    hit_range = _distance(ax, ay, basex + kx, basey + ky, startx, starty, cos_i, sin_i, ppm)
                    hit_cell = (iy + cy - cy0 - row0) * width + ix + cx - cx0 - col0
                    steps_left = 0.0
            else:
                if calculate_crossings:
                    calculate_crossings = False
                    # Stage's region corner, (int)(ix / REGION) * REGION less a region where globx < 0 and ix is
                    # not a multiple: always the multiple of REGION at or below ix (ix = 0 when -1 < globx < 0)
                    regionx = float(ix & -REGION)
                    regiony = float(iy & -REGION)
                    xdx = regionx - globx - 1.0 if sx < 0 else regionx + REGION - globx
                    xdy = xdx * tana
                    ydy = regiony - globy - 1.0 if sy < 0 else regiony + REGION - globy
                    ydx = ydy / tana
                    xcrossx, xcrossy = globx + xdx, globy + xdy
                    ycrossx, ycrossy = globx + ydx, globy + ydy
                    dist_x = abs(xdx) + abs(xdy)
                    dist_y = abs(ydx) + abs(ydy)
                kx = ky = 0  # the loop looks at the region jumped to again, as Stage's does
                if padded:
                    jumped = jump_through_stop_map(
                        basex, basey, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, steps_left, xjumpx, xjumpy,
                        yjumpx, yjumpy, xjumpdist, yjumpdist, stops, stop_row0, stop_col0)
                else:
                    jumped = jump_through_grid(
                        basex, basey, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, steps_left, xjumpx, xjumpy,
                        yjumpx, yjumpy, xjumpdist, yjumpdist, slots, robot_regions, use_regions, rrow0, rcol0)
                basex, basey, xcrossx, xcrossy, ycrossx, ycrossy, dist_x, dist_y, steps_left = jumped
        cell[i], rid[i] = hit_cell, hit_robot
        out[at] = hit_range if hit_cell >= 0 else rmax[i]


@numba.njit(**_JIT)
def cast_serial(world, robots, flags, place, stops, pad, marked, origins, origin_of, heading, local, jitter, trig,
                rmax, ppm, owner, out_at, out, cell, rid):
    """Every ray in order, on the calling thread: ranges in metres (exactly ``rmax`` on a miss) into
    ``out[out_at[i]]``, the cell and robot hit into ``cell[i]`` and ``rid[i]``.

    ``world``: (static row masks, static column masks, tile of each slot, slot of each region, rows used,
    columns used); ``robots``: (robot tile of each region, robot id per cell, robot row masks, robot column
    masks, per robot tile its rows and its columns holding a cell and its one robot) of a
    :class:`~stage_sim.sensing.robot_layer.RobotLayer`; ``flags``: (use its regions, use its cells);
    ``stops``, ``pad``: the :class:`~stage_sim.sensing.stop_map.StopMap` of the static regions and its margin,
    ``marked`` the robot layer's regions (flat), set in it for this cast when its regions are used;
    ``origins``: (K, 2) points rays start from, ray i from ``origin_of[i]`` (a ranger's beams share one)
    at angle ``heading[origin_of[i]] + local[i]`` (+ ``jitter[out_at[i]]`` unless ``jitter`` is empty);
    ``trig``: (angle, cos, sin) of each ``out_at`` slot's last cast, kept up to date (empty arrays: none);
    ``place``: col0, row0, rcol0, rrow0 of the :class:`~stage_sim.maps.tiles.TileGrid` and its width."""
    mark_robot_regions(stops, pad, world[3], marked, flags[0])
    _cast_range(world, robots, flags, place, stops, pad, origins, origin_of, heading, local, jitter, trig, rmax, ppm,
                owner, out_at, out, cell, rid, 0, owner.size)
    mark_robot_regions(stops, pad, world[3], marked, False)


@numba.njit(parallel=True, **_JIT)
def cast_parallel(world, robots, flags, place, stops, pad, marked, origins, origin_of, heading, local, jitter, trig,
                  rmax, ppm, owner, out_at, out, cell, rid):
    """Every ray, chunks of rays spread over numba's threads (each ray's answer is independent of them)."""
    mark_robot_regions(stops, pad, world[3], marked, flags[0])
    n = owner.size
    for k in numba.prange((n + _CHUNK - 1) // _CHUNK):
        _cast_range(world, robots, flags, place, stops, pad, origins, origin_of, heading, local, jitter, trig, rmax,
                    ppm, owner, out_at, out, cell, rid, k * _CHUNK, min(n, (k + 1) * _CHUNK))
    mark_robot_regions(stops, pad, world[3], marked, False)
