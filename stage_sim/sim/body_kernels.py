"""Compiled (numba) robot bodies: :class:`~stage_sim.sim.collision.CollisionChecker`'s raster and its one-by-one
move decisions, with the numpy reference's answers exactly.

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

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}

walk = numba.njit(**_JIT)(edge_walk)


@numba.njit(**_JIT)
def polygon_outline(vertices):
    """:func:`~stage_sim.maps.polygon_raster.edge_cells` of one closed polygon of vertex cells (M, 2): the cells of
    its walk, in the same order (an episode's new obstacles are traced with it)."""
    m, count = vertices.shape[0], 0
    for i in range(m):
        j = i + 1 if i + 1 < m else 0
        count += abs(vertices[j, 0] - vertices[i, 0]) + abs(vertices[j, 1] - vertices[i, 1])
    cells = np.empty((count, 2), dtype=np.int64)
    walk(vertices, cells, 0)
    return cells


@numba.njit(inline="always", **_JIT)
def _floored_vertices(vertices, a, b, x, y, cos, sin, ppm, out):
    """``out[:b - a]``: the world cells of vertices ``a`` to ``b`` placed at (x, y) facing (cos, sin)."""
    for v in range(a, b):
        out[v - a, 0] = math.floor((x + cos * vertices[v, 0] - sin * vertices[v, 1]) * ppm)
        out[v - a, 1] = math.floor((y + sin * vertices[v, 0] + cos * vertices[v, 1]) * ppm)


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
            _floored_vertices(vertices, a, b, x[r], y[r], cos[r], sin[r], ppm, scratch)
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
            _floored_vertices(vertices, a, b, x[r], y[r], cos[r], sin[r], ppm, scratch)
            m = walk(scratch[:b - a], cells, n)
            owner[n:m] = r
            n = m
    flat = np.empty(total, dtype=np.int64)
    for i in range(total):
        c, rr = cells[i, 0] - col0, cells[i, 1] - row0
        flat[i] = rr * width + c if 0 <= c < width and 0 <= rr < height else -1
    return flat, owner


@numba.njit(**_JIT)
def static_hits(cells, owner, layer_of_robot, layer, slots, tile_of_slot, bits, place, width, hit):
    """``hit[r] |= True`` for every robot r of height band ``layer`` with a cell (flat; −1 off the grid) in
    that band's :class:`~stage_sim.maps.tiles.TileLayer` (its slots, tiles and bits; ``place``: col0, row0,
    rcol0, rrow0), as :meth:`~stage_sim.maps.tiles.TileLayer.contains` says of each cell."""
    col0, row0, rcol0, rrow0 = place[0], place[1], place[2], place[3]
    for i in range(cells.size):
        r = owner[i]
        if cells[i] < 0 or hit[r] or layer_of_robot[r] != layer:
            continue
        wy = cells[i] // width + row0
        wx = cells[i] % width + col0
        slot = slots[(wy >> TILE_BITS) - rrow0, (wx >> TILE_BITS) - rcol0]
        if slot < 0:
            continue
        tile = tile_of_slot[slot]
        if tile >= 0:
            x = wx & (TILE - 1)
            hit[r] = (bits[tile, wy & (TILE - 1), x >> 3] >> (x & 7)) & 1 == 1


@numba.njit(**_JIT)
def _slices(owner, n):
    """(start, end) per robot of its cells in ``owner``: a raster lists each robot's cells together."""
    start = np.zeros(n, dtype=np.int64)
    end = np.zeros(n, dtype=np.int64)
    i = 0
    while i < owner.size:
        r = owner[i]
        j = i
        while j < owner.size and owner[j] == r:
            j += 1
        start[r], end[r] = i, j
        i = j
    return start, end


@numba.njit(**_JIT)
def _meet(a, b):
    """Whether boxes ``a`` and ``b`` (col min, row min, col max, row max) overlap."""
    return a[0] <= b[2] and b[0] <= a[2] and a[1] <= b[3] and b[1] <= a[3]


@numba.njit(**_JIT)
def _neighbours(box, robots):
    """CSR (start per robot, robots) of the pairs of ``robots`` whose boxes overlap: a sweep along x."""
    n = box.shape[0]
    order = robots[np.argsort(box[robots, 0], kind="mergesort")]
    count = np.zeros(n + 1, dtype=np.int64)
    for twice in range(2):  # count, then fill
        if twice:
            start = np.zeros(n + 1, dtype=np.int64)
            for r in range(n):
                start[r + 1] = start[r] + count[r]
            other = np.empty(start[n], dtype=np.int64)
            fill = start[:n].copy()
        for a in range(order.size):
            ra = order[a]
            for b in range(a + 1, order.size):
                rb = order[b]
                if box[rb, 0] > box[ra, 2]:
                    break
                if _meet(box[ra], box[rb]):
                    if twice:
                        other[fill[ra]] = rb
                        other[fill[rb]] = ra
                        fill[ra] += 1
                        fill[rb] += 1
                    else:
                        count[ra] += 1
                        count[rb] += 1
    return start, other


@numba.njit(**_JIT)
def _slot(keys, cell, mask):
    """The slot of ``cell`` in the open-addressing table ``keys`` (its own, or the empty one it would take)."""
    h = (cell * 2654435761) & mask
    while keys[h] != -1 and keys[h] != cell:
        h = (h + 1) & mask
    return h


@numba.njit(**_JIT)
def move_one_by_one(testers, static_hit, cand_cells, cand_owner, layer_cells, layer_owner, back_cells, back_owner,
                    present, box, refused):
    """:func:`~stage_sim.sim.collision.decide_moves`' answers by doing what Stage does: every obstacle robot
    (``present``) stands where the layer holds it (``layer_*``); each tester in turn is taken out, its end
    pose (``cand_*``) tested against the static answer and the cells of the robots that may touch it, and put
    back at its end pose or, refused, at its start pose (``back_*``). ``box[s, r]``: a world-cell box (col
    min, row min, col max, row max) holding robot r's cells in raster s (0 layer, 1 end, 2 start); robots
    are compared cell by cell only when their boxes meet (boxes swept along x once per update)."""
    n = refused.size
    sources = (layer_cells, cand_cells, back_cells)
    start = np.zeros((3, n), dtype=np.int64)
    end = np.zeros((3, n), dtype=np.int64)
    for s, owner in enumerate((layer_owner, cand_owner, back_owner)):
        start[s], end[s] = _slices(owner, n)
    reach = box[0].copy()  # every box a robot may have during this update
    for k in range(testers.size):
        i = testers[k]
        for s in (1, 2):
            reach[i, 0] = min(reach[i, 0], box[s, i, 0])
            reach[i, 1] = min(reach[i, 1], box[s, i, 1])
            reach[i, 2] = max(reach[i, 2], box[s, i, 2])
            reach[i, 3] = max(reach[i, 3], box[s, i, 3])
    near_start, near = _neighbours(reach, present)
    where = np.full(n, -1, dtype=np.int64)  # which raster holds each robot now: 0 layer, 1 end, 2 start
    where[present] = 0
    longest = 1
    for k in range(testers.size):
        longest = max(longest, end[1, testers[k]] - start[1, testers[k]])
    size = 16
    while size < 2 * longest:
        size *= 2
    mask = size - 1
    keys = np.empty(size, dtype=np.int64)
    for k in range(testers.size):
        i = testers[k]
        where[i] = -1
        hit = static_hit[i]
        filled = False
        m = near_start[i]
        while not hit and m < near_start[i + 1]:
            j = near[m]
            m += 1
            s = where[j]
            if s < 0 or not _meet(box[1, i], box[s, j]):
                continue
            if not filled:  # the tester's end cells, hashed once and only if some robot comes close
                keys[:] = -1
                for q in range(start[1, i], end[1, i]):
                    c = cand_cells[q]
                    if c >= 0:
                        keys[_slot(keys, c, mask)] = c
                filled = True
            cells = sources[s]
            for q in range(start[s, j], end[s, j]):
                c = cells[q]
                if c >= 0 and keys[_slot(keys, c, mask)] == c:
                    hit = True
                    break
        refused[i] = hit
        where[i] = 2 if hit else 1
