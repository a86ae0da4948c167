"""Compiled (numba) inner loops of :mod:`stage_sim.sim.collision`, with the numpy code's arithmetic exactly.

The trigonometry stays in numpy (the caller passes each pose's cos and sin, computed by the same numpy
calls as the reference), so the cells below are the reference's cells bit for bit. Loops over independent
items have a ``_parallel`` twin for more than one thread (the same answers, spread over numba's threads).
"""

from __future__ import annotations

import math

import numba

from stage_sim.maps.tiles import TILE, TILE_BITS

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


#: Work items of the parallel loops (points, robots): big enough that a thread's share is worth its start.
_CHUNK = 2048


@numba.njit(inline="always", **_JIT)
def point_row_col(x, y, cos, sin, px, py, resolution, ox, oy):
    """(row, col) of the grid cell under the body point (px, py) of a robot at (x, y) facing (cos, sin):
    the numpy reference's ``point_cells(place(...))`` for one point, before the grid's bounds."""
    return (math.floor((y + sin * px + cos * py - oy) / resolution),
            math.floor((x + cos * px - sin * py - ox) / resolution))


@numba.njit(inline="always", **_JIT)
def point_cell(x, y, cos, sin, px, py, resolution, ox, oy, height, width):
    """Flat cell (or -1 off the grid) of the body point (px, py) of a robot at (x, y) facing (cos, sin)."""
    row, col = point_row_col(x, y, cos, sin, px, py, resolution, ox, oy)
    return row * width + col if 0 <= col < width and 0 <= row < height else -1


@numba.njit(inline="always", **_JIT)
def _body_cells(points, pose_index, x, y, cos, sin, resolution, ox, oy, height, width, out, a, b):
    for i in range(a, b):
        p = pose_index[i]
        out[i] = point_cell(x[p], y[p], cos[p], sin[p], points[i, 0], points[i, 1], resolution, ox, oy, height,
                            width)


@numba.njit(**_JIT)
def body_cells(points, pose_index, x, y, cos, sin, resolution, ox, oy, height, width, out):
    """Flat cell (or -1 off the grid) of body point i placed at pose ``pose_index[i]``; the numpy
    reference is ``point_cells(place(points, poses[pose_index]))``."""
    _body_cells(points, pose_index, x, y, cos, sin, resolution, ox, oy, height, width, out, 0, points.shape[0])


@numba.njit(parallel=True, **_JIT)
def body_cells_parallel(points, pose_index, x, y, cos, sin, resolution, ox, oy, height, width, out):
    """:func:`body_cells`, chunks of points on numba's threads."""
    n = points.shape[0]
    for k in numba.prange((n + _CHUNK - 1) // _CHUNK):
        _body_cells(points, pose_index, x, y, cos, sin, resolution, ox, oy, height, width, out, k * _CHUNK,
                    min(n, (k + 1) * _CHUNK))


@numba.njit(inline="always", **_JIT)
def _robots_cells(points, first, count, robots, x, y, cos, sin, resolution, ox, oy, height, width, out, a, b):
    for k in range(a, b):
        p = robots[k]
        for i in range(first[p], first[p] + count[p]):
            out[i] = point_cell(x[p], y[p], cos[p], sin[p], points[i, 0], points[i, 1], resolution, ox, oy, height,
                                width)


@numba.njit(**_JIT)
def robots_cells(points, first, count, robots, x, y, cos, sin, resolution, ox, oy, height, width, out):
    """:func:`body_cells` of the points of ``robots`` only (robot r's points are ``first[r]`` on, ``count[r]``
    of them), written into their entries of ``out``."""
    _robots_cells(points, first, count, robots, x, y, cos, sin, resolution, ox, oy, height, width, out, 0,
                  robots.size)


@numba.njit(parallel=True, **_JIT)
def robots_cells_parallel(points, first, count, robots, x, y, cos, sin, resolution, ox, oy, height, width, out):
    """:func:`robots_cells`, groups of robots on numba's threads."""
    n = robots.size
    step = max(1, _CHUNK // 256)
    for k in numba.prange((n + step - 1) // step):
        _robots_cells(points, first, count, robots, x, y, cos, sin, resolution, ox, oy, height, width, out,
                      k * step, min(n, (k + 1) * step))


@numba.njit(**_JIT)
def owner_clashes(cells, robots, first, count, keys, robot, used, conflict):
    """Mark the robots of ``robots`` sharing a cell (robot r's points are ``first[r]`` on, ``count[r]`` of
    them; cell -1: off the grid, ignored) in an open-addressing table of the cells seen (``keys``, all -1, a
    power of two over twice the points; ``robot`` the first robot seen in each; ``used`` room for a slot per
    point): a later point of another robot in a cell flags both. The table is left empty again. The numpy
    reference sorts (cell, robot) pairs instead."""
    mask = keys.size - 1
    m = 0
    for k in range(robots.size):
        owner = robots[k]
        last_cell = -1
        for i in range(first[owner], first[owner] + count[owner]):
            cell = cells[i]
            if cell < 0 or cell == last_cell:
                continue
            last_cell = cell
            slot = (cell ^ (cell >> 16)) & mask  # neighbouring cells in neighbouring slots: few cache misses
            while keys[slot] != -1 and keys[slot] != cell:
                slot = (slot + 1) & mask
            if keys[slot] == -1:
                keys[slot] = cell
                robot[slot] = owner
                used[m] = slot
                m += 1
            elif robot[slot] != owner:
                conflict[robot[slot]] = True
                conflict[owner] = True
    for j in range(m):
        keys[used[j]] = -1


@numba.njit(inline="always", **_JIT)
def _near_robots(others, robots, poses, radius, margin, near, a, b):
    for k in range(a, b):
        j = others[k]
        for i in robots:
            dx = poses[j, 0] - poses[i, 0]
            dy = poses[j, 1] - poses[i, 1]
            if math.hypot(dx, dy) <= radius[j] + radius[i] + margin:
                near[k] = True
                break


@numba.njit(**_JIT)
def near_robots(others, robots, poses, radius, margin, near):
    """``near[k]``: whether robot ``others[k]`` lies within touching distance of one of ``robots`` (centres
    no farther apart than the two radii and ``margin``), as the numpy reference's distance matrix says."""
    _near_robots(others, robots, poses, radius, margin, near, 0, others.size)


@numba.njit(parallel=True, **_JIT)
def near_robots_parallel(others, robots, poses, radius, margin, near):
    """:func:`near_robots`, groups of ``others`` on numba's threads."""
    n = others.size
    step = 64
    for k in numba.prange((n + step - 1) // step):
        _near_robots(others, robots, poses, radius, margin, near, k * step, min(n, (k + 1) * step))


@numba.njit(**_JIT)
def crowded(robots, poses, radius, margin, out):
    """``out[k]``: whether robot ``robots[k]`` lies within touching distance of another of ``robots``
    (centres no farther apart than the two radii and ``margin``); ``out`` all False to begin with."""
    for a in range(robots.size):
        i = robots[a]
        for b in range(a + 1, robots.size):
            j = robots[b]
            if math.hypot(poses[j, 0] - poses[i, 0], poses[j, 1] - poses[i, 1]) <= radius[j] + radius[i] + margin:
                out[a] = True
                out[b] = True


@numba.njit(**_JIT)
def layer_contains(cells, slots, tile_of_slot, bits, place, width, out):
    """``out[i]``: whether flat cell ``cells[i]`` (-1: off the grid) is in a
    :class:`~stage_sim.maps.tiles.TileLayer` (its slots, tiles and bits; ``place``: col0, row0, rcol0,
    rrow0), as :meth:`~stage_sim.maps.tiles.TileLayer.contains` says."""
    col0, row0, rcol0, rrow0 = place[0], place[1], place[2], place[3]
    for i in range(cells.size):
        out[i] = False
        if cells[i] < 0:
            continue
        wy = cells[i] // width + row0
        wx = cells[i] % width + col0
        slot = slots[(wy >> TILE_BITS) - rrow0, (wx >> TILE_BITS) - rcol0]
        if slot < 0:
            continue
        tile = tile_of_slot[slot]
        if tile >= 0:
            x = wx & (TILE - 1)
            out[i] = (bits[tile, wy & (TILE - 1), x >> 3] >> (x & 7)) & 1 == 1
