"""Compiled (numba) exact ray traversal: the same answers as :mod:`stage_sim.sensing.raycast`, bit for bit.

One ray at a time, the plain per-cell walk of the reference (see the maths in
:mod:`stage_sim.sensing.raycast`): crossing times computed fresh from their grid line,
``t = (line − u) · (1 / d)``, minor axis first on ties, the answer being the entry time of the first
blocking cell. Robots are checked before the static map in every cell (a ray never sees its owner).

Free space is skipped without changing any answer. From the current cell the ray may jump over a
*free box* whose far edges lie on grid lines ``lx`` (x) and ``ly`` (y) ahead of it:

* the largest free square with the cell as its corner in the ray's quadrant
  (:func:`square_fields`, one uint8 per cell and quadrant; 0 marks an occupied cell);
* intersected, when robots are about, with the largest square of robot-free 8-cell blocks from the
  cell's block (the same square fields, on blocks), or else with the cell's own block if no robot but the
  ray's own is there (a ray never sees its own robot)
  (:class:`~stage_sim.sensing.fast_caster.RobotCells`);
* outside the grid, the half-plane beyond the grid edge (outside is free).

The jump lands exactly where the walk would: the box is left through the line with the earlier crossing
(tie rule included), and the other coordinate is the walk's own: a candidate from the position, then
corrected by comparing the crossing times of the lines around it with the exit time. Since the walk
compares the same fresh crossing times, it would have reached the same cell at the same time.
"""

from __future__ import annotations

import math

import numba
import numpy as np

#: Robot occupancy blocks: 2**BLOCK cells a side.
BLOCK = 3
#: Largest free-square side stored (uint8).
SQUARE_CAP = 255
#: A line "at infinity" for the half-planes outside the grid (cells, exact in float64).
_FAR = 1 << 40
#: Rays per work item of the parallel loop.
_CHUNK = 64

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(inline="always", **_JIT)
def _x_first(tx: float, ty: float, x_major: bool) -> bool:
    """Whether the walk crosses the x line at ``tx`` before the y line at ``ty`` (minor axis first on ties)."""
    return (tx < ty) if x_major else (tx <= ty)


@numba.njit(**_JIT)
def cast_ray(squares, robots, use_robots, blocks, block_squares, u, v, dx, dy, reach, owner):
    """(entry time in cells or inf, flat cell or -1, robot id or -1) of one ray from cell coordinates (u, v)."""
    h, w = squares.shape[1], squares.shape[2]
    idx = 1.0 / dx
    idy = 1.0 / dy
    x_major = abs(dx) >= abs(dy)
    sx = 1 if dx >= 0 else -1
    sy = 1 if dy >= 0 else -1
    ax = 1 if dx >= 0 else 0
    ay = 1 if dy >= 0 else 0
    quadrant = (1 - ax) + 2 * (1 - ay)
    square = squares[quadrant]
    if not (abs(u) < 1e15 and abs(v) < 1e15):  # also NaN
        return math.inf, -1, -1
    ix = math.floor(u)
    iy = math.floor(v)
    t = 0.0
    while True:
        if 0 <= ix < w and 0 <= iy < h:
            k = np.int64(square[iy, ix])
            if use_robots:  # a square of robot-free blocks, or a block with no robot but the ray's own
                bx = ix >> BLOCK
                by = iy >> BLOCK
                side = np.int64(block_squares[quadrant, by, bx])
                if side == 0:
                    block = blocks[by, bx]
                    if block == -1 or block == owner:
                        side = 1
                    else:
                        rid = robots[iy, ix]
                        if rid != -1 and rid != owner:
                            return t, iy * w + ix, rid
                        k = min(k, 1)
            if k == 0:
                return t, iy * w + ix, -1
            if k == 1:  # next to an obstacle: one plain step
                tx = ((ix + ax) - u) * idx
                ty = ((iy + ay) - v) * idy
                if _x_first(tx, ty, x_major):
                    t = tx
                    ix += sx
                else:
                    t = ty
                    iy += sy
                if t >= reach:
                    return math.inf, -1, -1
                continue
            lx = ix + sx * k + (1 - ax)
            ly = iy + sy * k + (1 - ay)
            if use_robots:
                blx = (bx + sx * (side - 1) + ax) << BLOCK
                bly = (by + sy * (side - 1) + ay) << BLOCK
                lx = min(lx, blx) if sx > 0 else max(lx, blx)
                ly = min(ly, bly) if sy > 0 else max(ly, bly)
        elif ix < 0 or ix >= w:
            if (ix < 0) == (sx < 0) or dx == 0.0:
                return math.inf, -1, -1  # moving away from the grid
            lx = 0 if ix < 0 else w
            ly = iy + sy * _FAR
        else:
            if (iy < 0) == (sy < 0) or dy == 0.0:
                return math.inf, -1, -1
            ly = 0 if iy < 0 else h
            lx = ix + sx * _FAR
        tx = (lx - u) * idx
        ty = (ly - v) * idy
        if _x_first(tx, ty, x_major):
            t = tx
            iy = _reached(v, idy, dy, tx, iy, ly, sy, ay, x_major, True)
            ix = lx if sx > 0 else lx - 1
        else:
            t = ty
            ix = _reached(u, idx, dx, ty, ix, lx, sx, ax, x_major, False)
            iy = ly if sy > 0 else ly - 1
        if t >= reach:
            return math.inf, -1, -1


@numba.njit(inline="always", **_JIT)
def _reached(p, inv, d, t_exit, i, line, s, a, x_major, other_is_y):
    """The walk's cell index on the other axis when it leaves the box at ``t_exit`` (from cell ``i``).

    ``line`` is the box's far line on this axis (never reached: the box is left through the other axis).
    A line on this axis is crossed before the exit iff the walk orders its crossing first.
    """
    last = line - 1 if s > 0 else line
    c = p + t_exit * d
    j = math.floor(c) if abs(c) < 1e15 else i
    j = min(max(j, i), last) if s > 0 else max(min(j, i), last)
    while j != last:  # the line ahead of j crossed before the exit: one more cell
        t_line = ((j + a) - p) * inv
        crossed = not _x_first(t_exit, t_line, x_major) if other_is_y else _x_first(t_line, t_exit, x_major)
        if not crossed:
            break
        j += s
    while j != i:  # the line behind j not crossed yet: one cell back
        t_line = ((j + 1 - a) - p) * inv
        crossed = not _x_first(t_exit, t_line, x_major) if other_is_y else _x_first(t_line, t_exit, x_major)
        if crossed:
            break
        j -= s
    return j


@numba.njit(**_JIT)
def _cast_range(squares, robots, use_robots, blocks, block_squares, u, v, dx, dy, reach, owner, t, cell, rid, a, b):
    for i in range(a, b):
        t[i], cell[i], rid[i] = cast_ray(squares, robots, use_robots, blocks, block_squares, u[i], v[i], dx[i], dy[i],
                                         reach[i], owner[i])


@numba.njit(**_JIT)
def cast_serial(squares, robots, use_robots, blocks, block_squares, u, v, dx, dy, reach, owner, t, cell, rid):
    """Every ray in order, on the calling thread."""
    _cast_range(squares, robots, use_robots, blocks, block_squares, u, v, dx, dy, reach, owner, t, cell, rid, 0, u.size)


@numba.njit(parallel=True, **_JIT)
def cast_parallel(squares, robots, use_robots, blocks, block_squares, u, v, dx, dy, reach, owner, t, cell, rid):
    """Every ray, chunks of rays spread over numba's threads (each ray's answer is independent of them)."""
    n = u.size
    for k in numba.prange((n + _CHUNK - 1) // _CHUNK):
        _cast_range(squares, robots, use_robots, blocks, block_squares, u, v, dx, dy, reach, owner, t, cell, rid,
                    k * _CHUNK, min(n, (k + 1) * _CHUNK))


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
