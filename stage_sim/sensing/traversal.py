"""Compiled (numba) Stage ray walk: the same answers as :mod:`stage_sim.sensing.raycast`, bit for bit.

One ray at a time, Stage's walk as :mod:`stage_sim.sensing.stage_walk` states it (why Stage's and not the
true ray's: see there), statement for statement where it decides anything: the region test, the region
jumps with their crossings, the error term, the step count, the reported distance. Robots are checked
before the static map in every cell (a ray never sees its owner).

Free space inside a region holding blocks is crossed in one go without changing any answer: from the
current cell the walk may take any number of steps that keep it inside

* the largest free square with the cell as its corner in the ray's quadrant (:func:`square_fields`, one
  uint8 per cell and quadrant; 0 marks an occupied cell);
* the square of robot-free 8-cell blocks from the cell's block, when robots are about (or the cell's own
  block if no robot but the ray's own is there) (:class:`~stage_sim.sensing.fast_caster.RobotCells`);
* the largest square of regions holding blocks from the cell's region (:func:`region_squares`), and the
  current region itself unless the cells Stage would look up afresh on crossing a region border are the
  cells walked (:func:`_rereads_agree`);

and within its remaining step count; the cell reached is free, so the next step follows at once. Where the
walk stands after i steps along x and j along y is known in closed form (:func:`walk_prefix`), so the jump
lands on the very cell, error term and count of the walk; short stretches are stepped through (cheaper).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from stage_sim.sensing.robot_layer import BLOCK
from stage_sim.sensing.stage_walk import REGION, REGION_BITS

#: Largest free-square side stored (uint8).
SQUARE_CAP = 255
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
def _rereads_agree(basex, basey, kx, ky, gx, gy, di, dj):
    """Whether Stage's fresh look at ``int(globx), int(globy)`` on crossing a region border gives the cell walked.

    It does unless a coordinate changes sign on the way or ``base + k`` rounds onto a whole number; both would
    show at one end of the stretch (the truncation is monotonic in the magnitude), so both ends are checked.
    """
    return (int(basex + kx) == gx and int(basey + ky) == gy and int(basex + (kx + di)) == gx + di
            and int(basey + (ky + dj)) == gy + dj)


@numba.njit(inline="always", **_JIT)
def _prefix(e, bx, by, mx, my, n):
    """:func:`walk_prefix`, step by step for short stretches (cheaper than its divisions)."""
    if mx + my > JUMP_STEPS:
        return walk_prefix(e, bx, by, mx, my, n)
    return _step_through(e, bx, by, mx, my, n)


@numba.njit(**_JIT)
def walk_ray(squares, robots, use_robots, blocks, block_squares, regions, region_squares, col0, row0, rcol0, rrow0,
             startx, starty, cosa, sina, tana, dx, dy, ppm, owner):
    """(range in metres or inf, flat cell or -1, robot id or -1) of one ray walked as Stage walks it."""
    h, w = squares.shape[1], squares.shape[2]
    rh, rw = regions.shape
    sx = 1 if dx > 0 else (-1 if dx < 0 else 0)
    sy = 1 if dy > 0 else (-1 if dy < 0 else 0)
    ax = np.int64(abs(dx))
    ay = np.int64(abs(dy))
    bx, by = 2 * ax, 2 * ay
    exy = ay - ax
    n = ax + ay
    quadrant = (1 if sx < 0 else 0) + (2 if sy < 0 else 0)
    square = squares[quadrant]
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
        if 0 <= rr < rh and 0 <= rc < rw and regions[rr, rc]:
            calculate_crossings = True
            cx, cy = ix & (REGION - 1), iy & (REGION - 1)
            r, c = iy - row0, ix - col0
            while 0 <= cx < REGION and 0 <= cy < REGION and n > 0:
                k = 1
                kbx = kby = SQUARE_CAP
                if 0 <= r < h and 0 <= c < w:
                    k = np.int64(square[r, c])
                    if use_robots:  # a square of robot-free blocks, or a block with no robot but the ray's own
                        bbx, bby = c >> BLOCK, r >> BLOCK
                        side = np.int64(block_squares[quadrant, bby, bbx])
                        if side == 0:
                            block = blocks[bby, bbx]
                            if block == -1 or block == owner:
                                side = 1
                            else:
                                rid = robots[r, c]
                                if rid != -1 and rid != owner:
                                    return _distance(ax, ay, basex + kx, basey + ky, startx, starty, cosa, sina,
                                                     ppm), r * w + c, rid
                                k = min(k, 1)
                        kbx = ((bbx + side) << BLOCK) - c if sx >= 0 else c + 1 - ((bbx - side + 1) << BLOCK)
                        kby = ((bby + side) << BLOCK) - r if sy >= 0 else r + 1 - ((bby - side + 1) << BLOCK)
                    if k == 0:
                        return _distance(ax, ay, basex + kx, basey + ky, startx, starty, cosa, sina, ppm), r * w + c, -1
                if k > 1:
                    gx, gy = c + col0, r + row0
                    rgx, rgy = gx >> REGION_BITS, gy >> REGION_BITS
                    side = np.int64(region_squares[quadrant, rgy - rrow0, rgx - rcol0])
                    krx = ((rgx + side) << REGION_BITS) - gx if sx >= 0 else gx + 1 - ((rgx - side + 1) << REGION_BITS)
                    kry = ((rgy + side) << REGION_BITS) - gy if sy >= 0 else gy + 1 - ((rgy - side + 1) << REGION_BITS)
                    mx = min(k, kbx, krx) - 1
                    my = min(k, kby, kry) - 1
                    i, j = _prefix(exy, bx, by, mx, my, n)
                    ex, ey = cx + i * sx, cy + j * sy
                    if not (0 <= ex < REGION and 0 <= ey < REGION) and not _rereads_agree(
                            basex, basey, kx, ky, gx, gy, i * sx, j * sy):
                        mx = min(mx, REGION - 1 - cx if sx > 0 else cx)
                        my = min(my, REGION - 1 - cy if sy > 0 else cy)
                        i, j = _prefix(exy, bx, by, mx, my, n)
                    if i + j > 0:
                        kx += i * sx
                        c += i * sx
                        ky += j * sy
                        r += j * sy
                        cx = (c + col0) & (REGION - 1)
                        cy = (r + row0) & (REGION - 1)
                        exy += i * by - j * bx
                        n -= i + j
                        if n <= 0:
                            continue
                        # Stage looks at this cell too: free (inside the square), so on with the next step.
                if exy < 0:
                    kx += sx
                    exy += by
                    cx += sx
                    c += sx
                else:
                    ky += sy
                    exy -= bx
                    cy += sy
                    r += sy
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
def _cast_range(squares, robots, use_robots, blocks, block_squares, regions, region_squares, place, xy, cosa, sina,
                rmax, ppm, owner, out, cell, rid, a, b):
    col0, row0, rcol0, rrow0 = place[0], place[1], place[2], place[3]
    for i in range(a, b):
        c, s = cosa[i], sina[i]
        reach = ppm * rmax[i]  # the arithmetic of stage_walk.WalkRays, operation for operation
        walked, cell[i], rid[i] = walk_ray(squares, robots, use_robots, blocks, block_squares, regions,
                                           region_squares, col0, row0, rcol0, rrow0, xy[i, 0] * ppm, xy[i, 1] * ppm,
                                           c, s, s / c, reach * c, reach * s, ppm, owner[i])
        out[i] = walked if cell[i] >= 0 else rmax[i]


@numba.njit(**_JIT)
def cast_serial(squares, robots, use_robots, blocks, block_squares, regions, region_squares, place, xy, cosa, sina,
                rmax, ppm, owner, out, cell, rid):
    """Every ray in order, on the calling thread: ranges in metres (exactly ``rmax`` on a miss) into ``out``.

    ``cosa``, ``sina``: of Stage's beam angles (:func:`~stage_sim.sensing.stage_walk.beam_cos_sin`);
    ``place``: col0, row0, rcol0, rrow0 of :class:`~stage_sim.sensing.stage_walk.WalkGrid`."""
    _cast_range(squares, robots, use_robots, blocks, block_squares, regions, region_squares, place, xy, cosa, sina,
                rmax, ppm, owner, out, cell, rid, 0, owner.size)


@numba.njit(parallel=True, **_JIT)
def cast_parallel(squares, robots, use_robots, blocks, block_squares, regions, region_squares, place, xy, cosa, sina,
                  rmax, ppm, owner, out, cell, rid):
    """Every ray, chunks of rays spread over numba's threads (each ray's answer is independent of them)."""
    n = owner.size
    for k in numba.prange((n + _CHUNK - 1) // _CHUNK):
        _cast_range(squares, robots, use_robots, blocks, block_squares, regions, region_squares, place, xy, cosa,
                    sina, rmax, ppm, owner, out, cell, rid, k * _CHUNK, min(n, (k + 1) * _CHUNK))


@numba.njit(**_JIT)
def square_fields(occupied):
    """(4, H, W) uint8: side of the largest free square with the cell as its corner, towards quadrant q.

    q = (dx < 0) + 2·(dy < 0); cells beyond the grid are free; 0 iff the cell is occupied; capped at
    :data:`SQUARE_CAP`. The recurrence k = 1 + min(k(x+sx), k(y+sy), k(x+sx, y+sy)).
    """
    h, w = occupied.shape
    out = np.empty((4, h, w), dtype=np.uint8)
    for q in range(4):
        sx = -1 if q & 1 else 1
        sy = -1 if q & 2 else 1
        for j in range(h):
            y = h - 1 - j if sy > 0 else j
            for i in range(w):
                x = w - 1 - i if sx > 0 else i
                if occupied[y, x]:
                    out[q, y, x] = 0
                    continue
                xn, yn = x + sx, y + sy
                x_in, y_in = 0 <= xn < w, 0 <= yn < h
                side = SQUARE_CAP
                if x_in:
                    side = min(side, np.int64(out[q, y, xn]))
                if y_in:
                    side = min(side, np.int64(out[q, yn, x]))
                if x_in and y_in:
                    side = min(side, np.int64(out[q, yn, xn]))
                out[q, y, x] = min(side + 1, SQUARE_CAP)
    return out


def region_squares(regions: np.ndarray) -> np.ndarray:
    """(4, R, C) uint8: side of the largest square of regions holding blocks from each region, per quadrant
    (0 for an empty region; regions beyond the grid are empty)."""
    padded = np.ones((regions.shape[0] + 2, regions.shape[1] + 2), dtype=np.bool_)
    padded[1:-1, 1:-1] = ~regions
    return np.ascontiguousarray(square_fields(padded)[:, 1:-1, 1:-1])


@numba.njit(**_JIT)
def write_robot_cells(grid, blocks, old, flat, ids, several):
    """Clear the cells ``old`` of ``grid``, then write robot ``ids[i]`` into cell ``flat[i]``.

    A cell written by two robots holds ``several``. ``blocks`` says per block which robots have cells
    there: -1 none, ``several`` two or more, else the one robot's id.
    """
    w = grid.shape[1]
    g = grid.ravel()
    for f in old:
        g[f] = -1
        r, c = f // w, f % w
        blocks[r >> BLOCK, c >> BLOCK] = -1
    for i in range(flat.size):
        f = flat[i]
        robot = ids[i]
        g[f] = robot if g[f] == -1 or g[f] == robot else several
        r, c = f // w, f % w
        b = blocks[r >> BLOCK, c >> BLOCK]
        blocks[r >> BLOCK, c >> BLOCK] = robot if b == -1 or b == robot else several
