"""Compiled (numba) robot bodies: :class:`~stage_sim.sim.collision.CollisionChecker`'s raster and its one-by-one
move decisions, with the numpy reference's arithmetic exactly.

The raster walks each polygon with :func:`~stage_sim.maps.polygon_raster.edge_walk` (the walk the static
blocks take, compiled here) after placing and flooring its vertices as the reference does; the trigonometry
stays in numpy (the caller passes each pose's cos and sin), so every cell is the reference's bit for bit.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from stage_sim.maps.polygon_raster import edge_walk
from stage_sim.maps.tiles import TILE, TILE_BITS
from stage_sim.sim.collision import decide_moves

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}

walk = numba.njit(**_JIT)(edge_walk)
decide = numba.njit(**_JIT)(decide_moves)


@numba.njit(**_JIT)
def body_raster(vertices, poly_start, robot_poly, robots, x, y, cos, sin, ppm, col0, row0, height, width):
    """(flat cell or −1 off the grid, robot) of every cell of the bodies of ``robots`` placed at (x, y) facing
    (cos, sin) (per robot), robot by robot, polygon by polygon: the reference's ``CollisionChecker._raster``."""
    longest = 0
    for k in range(robots.size):
        r = robots[k]
        for p in range(robot_poly[r], robot_poly[r + 1]):
            longest = max(longest, poly_start[p + 1] - poly_start[p])
    scratch = np.empty((max(longest, 1), 2), dtype=np.int64)
    total = 0
    for k in range(robots.size):  # first pass: the number of cells
        r = robots[k]
        for p in range(robot_poly[r], robot_poly[r + 1]):
            a, b = poly_start[p], poly_start[p + 1]
            for v in range(a, b):
                scratch[v - a, 0] = math.floor((x[r] + cos[r] * vertices[v, 0] - sin[r] * vertices[v, 1]) * ppm)
                scratch[v - a, 1] = math.floor((y[r] + sin[r] * vertices[v, 0] + cos[r] * vertices[v, 1]) * ppm)
            for v in range(b - a):
                w = v + 1 if v + 1 < b - a else 0
                total += abs(scratch[w, 0] - scratch[v, 0]) + abs(scratch[w, 1] - scratch[v, 1])
    cells = np.empty((total, 2), dtype=np.int64)
    owner = np.empty(total, dtype=np.int64)
    n = 0
    for k in range(robots.size):
        r = robots[k]
        for p in range(robot_poly[r], robot_poly[r + 1]):
            a, b = poly_start[p], poly_start[p + 1]
            for v in range(a, b):
                scratch[v - a, 0] = math.floor((x[r] + cos[r] * vertices[v, 0] - sin[r] * vertices[v, 1]) * ppm)
                scratch[v - a, 1] = math.floor((y[r] + sin[r] * vertices[v, 0] + cos[r] * vertices[v, 1]) * ppm)
            m = walk(scratch[:b - a], cells, n)
            owner[n:m] = r
            n = m
    flat = np.empty(total, dtype=np.int64)
    for i in range(total):
        c, rr = cells[i, 0] - col0, cells[i, 1] - row0
        flat[i] = rr * width + c if 0 <= c < width and 0 <= rr < height else -1
    return flat, owner


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
