"""Compiled (numba) Stage ray walk: the same answers as :mod:`stage_sim.sensing.raycast`, bit for bit.

One ray at a time, Stage's walk as :mod:`stage_sim.sensing.stage_walk` states it (why Stage's and not the
true ray's: see there), statement for statement where it decides anything: the region test, the region
jumps with their crossings, the error term, the step count, the reported distance. Robots are checked
before the static map in every cell (a ray never sees its owner).

The world is read through its tiles (:mod:`stage_sim.maps.tiles`): a region holds blocks if it has a static
slot or robot cells; on entering one, the walk looks up its static tile (none: every cell free at this
height) and its robot tile once. Free space inside the region is crossed in one go without changing any
answer: from the current cell the walk may take any number of steps that keep it inside

* the largest free square with the cell as its corner in the ray's quadrant, within the tile
  (:func:`~stage_sim.sensing.distance_field.tile_square_fields`; 0 marks an occupied cell; a region
  without a static tile: the square up to the region's border);
* the square of robot-free 8-cell blocks from the cell's block within the tile, when robots are about (or
  the cell's own block if no robot but the ray's own is there)
  (:class:`~stage_sim.sensing.robot_layer.RobotLayer`);

and within its remaining step count; the cell reached is free and in the region, so the next step follows
at once. Where the walk stands after i steps along x and j along y is known in closed form
(:func:`walk_prefix`), so the jump lands on the very cell, error term and count of the walk; short
stretches are stepped through (cheaper).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from stage_sim.sensing.distance_field import SQUARE_CAP
from stage_sim.sensing.stage_walk import BLOCK, REGION, REGION_BITS

#: Free stretches longer than this (steps) are crossed by :func:`walk_prefix`'s arithmetic, shorter ones
#: step by step.
JUMP_STEPS = 40
#: Rays per work item of the parallel loop.
_CHUNK = 64

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(inline="always", **_JIT)
def walk_prefix(e0, bx, by, mx, my, n):
    """(i, j): the most steps along x (i <= mx) and y (j <= my), i + j <= n, the walk takes from error e0.

    After i x-steps the walk has taken ``(e0 + (i − 1)·by) // bx + 1`` y-steps and takes y-steps until
    ``(e0 + i·by) // bx + 1`` (the error ``e0 + i·by − j·bx`` stays in [−bx, by)).
    """
    if bx == 0:
        return 0, min(my, n)
    i = mx
    room = my * bx - e0  # x-step i happens after (e0 + (i - 1)·by) // bx + 1 y-steps: at most my
    if room <= 0:
        i = 0
    elif by > 0:
        i = min(i, _floordiv(room - 1, by) + 1)
    if i > 0:
        i = min(i, max(0, _floordiv(n * bx + by - e0 - 1, bx + by)))
    j = min(_floordiv(e0 + i * by, bx) + 1, my, n - i)
    return i, j


@numba.njit(inline="always", **_JIT)
def _floordiv(a, b):
    """``a // b`` for b > 0 (|a| < 2**50): a float division, corrected to the exact integer quotient."""
    q = np.int64(math.floor(a / b))
    if q * b > a:
        q -= 1
    elif (q + 1) * b <= a:
        q += 1
    return q


@numba.njit(inline="always", **_JIT)
def _step_through(e, bx, by, mx, my, n):
    """:func:`walk_prefix` one step at a time: cheaper than its divisions for short stretches."""
    i = j = 0
    while n > 0:
        if e < 0:
            if i == mx:
                break
            i += 1
            e += by
        else:
            if j == my:
                break
            j += 1
            e -= bx
        n -= 1
    return i, j


@numba.njit(inline="always", **_JIT)
def _prefix(e, bx, by, mx, my, n):
    """:func:`walk_prefix`, step by step for short stretches (cheaper than its divisions)."""
    if mx + my > JUMP_STEPS:
        return walk_prefix(e, bx, by, mx, my, n)
    return _step_through(e, bx, by, mx, my, n)


@numba.njit(inline="always", **_JIT)
def walk_ray(squares, tile_of_slot, slots, robot_regions, robot_ids, robot_blocks, block_squares, use_regions,
             use_robots, col0, row0, rcol0, rrow0, width, startx, starty, cosa, sina, tana, dx, dy, ppm, owner):
    """(range in metres or inf, flat cell or -1, robot id or -1) of one ray walked as Stage walks it.

    Inlined into the loop over rays: a call passing seven arrays cost as much as a short ray's walk (1000
    jammed robots: 72 → 51 ms per cast of 240,000 rays), for 5 s more of the one-off compilation."""
    rh, rw = slots.shape
    sx = 1 if dx > 0 else (-1 if dx < 0 else 0)
    sy = 1 if dy > 0 else (-1 if dy < 0 else 0)
    ax = np.int64(abs(dx))
    ay = np.int64(abs(dy))
    bx, by = 2 * ax, 2 * ay
    exy = ay - ax
    n = ax + ay
    quadrant = (1 if sx < 0 else 0) + (2 if sy < 0 else 0)
    xjumpx, xjumpy = float(sx * REGION), (sx * REGION) * tana
    yjumpx, yjumpy = (sy * REGION) / tana, float(sy * REGION)
    xjumpdist = abs(xjumpx) + abs(xjumpy)
    yjumpdist = abs(yjumpx) + abs(yjumpy)
    xcrossx = xcrossy = ycrossx = ycrossy = dist_x = dist_y = 0.0
    basex, basey = startx, starty  # globx = basex + kx: whole steps since the start or the last jump
    kx = ky = 0
    calculate_crossings = True
    while n > 0:
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
            tile = tile_of_slot[slot] if slot >= 0 else -1
            cx, cy = ix & (REGION - 1), iy & (REGION - 1)
            while 0 <= cx < REGION and 0 <= cy < REGION and n > 0:
                if tile >= 0:
                    k = np.int64(squares[tile, quadrant, cy, cx])
                else:  # nothing static at this height in the region: free up to its border
                    k = min(REGION - cx if sx > 0 else cx + 1, REGION - cy if sy > 0 else cy + 1)
                kbx = kby = SQUARE_CAP
                if use_robots and rtile >= 0:  # a square of robot-free blocks, or a block with no robot but ours
                    bbx, bby = cx >> BLOCK, cy >> BLOCK
                    side = np.int64(block_squares[rtile, quadrant, bby, bbx])
                    if side == 0:
                        block = robot_blocks[rtile, bby, bbx]
                        if block == -1 or block == owner:
                            side = 1
                        else:
                            rid = robot_ids[rtile, cy, cx]
                            if rid != -1 and rid != owner:
                                return _distance(ax, ay, basex + kx, basey + ky, startx, starty, cosa, sina,
                                                 ppm), (iy - row0) * width + ix - col0, rid
                            k = min(k, 1)
                    kbx = ((bbx + side) << BLOCK) - cx if sx >= 0 else cx + 1 - ((bbx - side + 1) << BLOCK)
                    kby = ((bby + side) << BLOCK) - cy if sy >= 0 else cy + 1 - ((bby - side + 1) << BLOCK)
                if k == 0:
                    return (_distance(ax, ay, basex + kx, basey + ky, startx, starty, cosa, sina, ppm),
                            (iy - row0) * width + ix - col0, -1)
                if k > 1:
                    i, j = _prefix(exy, bx, by, min(k, kbx) - 1, min(k, kby) - 1, n)
                    if i + j > 0:
                        kx += i * sx
                        ix += i * sx
                        cx += i * sx
                        ky += j * sy
                        iy += j * sy
                        cy += j * sy
                        exy += i * by - j * bx
                        n -= i + j
                        if n <= 0:
                            continue
                        # Stage looks at this cell too: free (inside the square), so on with the next step.
                if exy < 0:
                    kx += sx
                    exy += by
                    cx += sx
                    ix += sx
                else:
                    ky += sy
                    exy -= bx
                    cy += sy
                    iy += sy
                n -= 1
        else:
            if calculate_crossings:
                calculate_crossings = False
                regionx = float(int(ix / REGION) * REGION)
                regiony = float(int(iy / REGION) * REGION)
                if globx < 0 and ix % REGION != 0:
                    regionx -= REGION
                if globy < 0 and iy % REGION != 0:
                    regiony -= REGION
                xdx = regionx - globx - 1.0 if sx < 0 else regionx + REGION - globx
                xdy = xdx * tana
                ydy = regiony - globy - 1.0 if sy < 0 else regiony + REGION - globy
                ydx = ydy / tana
                xcrossx, xcrossy = globx + xdx, globy + xdy
                ycrossx, ycrossy = globx + ydx, globy + ydy
                dist_x = abs(xdx) + abs(xdy)
                dist_y = abs(ydx) + abs(ydy)
            kx = ky = 0
            if dist_x < dist_y:
                basex, basey = xcrossx, xcrossy
                n = np.int64(n - dist_x)
                xcrossx += xjumpx
                xcrossy += xjumpy
                dist_y -= dist_x
                dist_x = xjumpdist
            else:
                basex, basey = ycrossx, ycrossy
                n = np.int64(n - dist_y)
                ycrossx += yjumpx
                ycrossy += yjumpy
                dist_x -= dist_y
                dist_y = yjumpdist
    return math.inf, -1, -1


@numba.njit(inline="always", **_JIT)
def _distance(ax, ay, globx, globy, startx, starty, cosa, sina, ppm):
    """Stage's reported range: the distance travelled along the major axis, in metres."""
    if ax > ay:
        return abs((globx - startx) / cosa) / ppm
    return abs((globy - starty) / sina) / ppm


@numba.njit(**_JIT)
def _cast_range(world, robots, flags, place, xy, cosa, sina, rmax, ppm, owner, out, cell, rid, a, b):
    squares, tile_of_slot, slots = world
    robot_regions, robot_ids, robot_blocks, block_squares = robots
    use_regions, use_robots = flags[0], flags[1]
    col0, row0, rcol0, rrow0, width = place[0], place[1], place[2], place[3], place[4]
    for i in range(a, b):
        c, s = cosa[i], sina[i]
        reach = ppm * rmax[i]  # the arithmetic of stage_walk.WalkRays, operation for operation
        walked, cell[i], rid[i] = walk_ray(squares, tile_of_slot, slots, robot_regions, robot_ids, robot_blocks,
                                           block_squares, use_regions, use_robots, col0, row0, rcol0, rrow0, width,
                                           xy[i, 0] * ppm, xy[i, 1] * ppm, c, s, s / c, reach * c, reach * s, ppm,
                                           owner[i])
        out[i] = walked if cell[i] >= 0 else rmax[i]


@numba.njit(**_JIT)
def cast_serial(world, robots, flags, place, xy, cosa, sina, rmax, ppm, owner, out, cell, rid):
    """Every ray in order, on the calling thread: ranges in metres (exactly ``rmax`` on a miss) into ``out``.

    ``world``: (static tile squares, tile of each slot, slot of each region); ``robots``: the arrays of a
    :class:`~stage_sim.sensing.robot_layer.RobotLayer`; ``flags``: (use its regions, use its cells);
    ``cosa``, ``sina``: of Stage's beam angles (:func:`~stage_sim.sensing.stage_walk.beam_cos_sin`);
    ``place``: col0, row0, rcol0, rrow0 of the :class:`~stage_sim.maps.tiles.TileGrid` and its width."""
    _cast_range(world, robots, flags, place, xy, cosa, sina, rmax, ppm, owner, out, cell, rid, 0, owner.size)


@numba.njit(parallel=True, **_JIT)
def cast_parallel(world, robots, flags, place, xy, cosa, sina, rmax, ppm, owner, out, cell, rid):
    """Every ray, chunks of rays spread over numba's threads (each ray's answer is independent of them)."""
    n = owner.size
    for k in numba.prange((n + _CHUNK - 1) // _CHUNK):
        _cast_range(world, robots, flags, place, xy, cosa, sina, rmax, ppm, owner, out, cell, rid, k * _CHUNK,
                    min(n, (k + 1) * _CHUNK))


@numba.njit(**_JIT)
def tile_square_fields(occupied):
    """:func:`stage_sim.sensing.distance_field.tile_square_fields`, compiled: (T, 4, S, S) uint8 sides of the
    largest free square within the tile from each cell towards quadrant q, by ``k = 1 + min(k(x+sx),
    k(y+sy), k(x+sx, y+sy))`` with cells beyond the tile occupied (side 0)."""
    t, s = occupied.shape[0], occupied.shape[1]
    out = np.empty((t, 4, s, s), dtype=np.uint8)
    for tile in range(t):
        for q in range(4):
            sx = -1 if q & 1 else 1
            sy = -1 if q & 2 else 1
            for j in range(s):
                y = s - 1 - j if sy > 0 else j
                for i in range(s):
                    x = s - 1 - i if sx > 0 else i
                    if occupied[tile, y, x]:
                        out[tile, q, y, x] = 0
                        continue
                    xn, yn = x + sx, y + sy
                    side = 0
                    if 0 <= xn < s and 0 <= yn < s:
                        side = min(out[tile, q, y, xn], out[tile, q, yn, x], out[tile, q, yn, xn])
                    out[tile, q, y, x] = side + 1
    return out
