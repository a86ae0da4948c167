"""Compiled (numba) moves against the static world: :meth:`CollisionChecker.resolve`'s candidate poses and
sub-stepped static test in two passes, with the numpy reference's arithmetic exactly.

Why: for a few robots the reference spends its time in some forty small numpy calls per step (repeats,
cumulative sums, fancy indexing), not in arithmetic. As everywhere in the kernels the trigonometry stays in
numpy: the caller passes the cosines and sines, so every probe pose and cell is the reference's bit for bit
(``tests/sim/test_kernel_identity.py`` runs whole simulations both ways).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from stage_sim.maps.tiles import TILE, TILE_BITS
from stage_sim.sim.collision_kernels import point_row_col
from stage_sim.sim.motion_kernels import normalize

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(**_JIT)
def probe_poses(poses, velocities, dt, movers, speed, radius, min_width, resolution, cos_a, sin_a):
    """The poses at which each mover's body is tested: ``substeps`` evenly spaced fractions of its move.

    ``speed``: ``np.hypot(vx, vy)`` per robot; ``cos_a``, ``sin_a``: of ``poses[:, 2]``. Returns
    (x, y, heading, robot) of every probe, movers in order, the fractions ascending (the reference's
    ``np.repeat``/``fraction`` layout)."""
    substeps = np.empty(movers.size, dtype=np.int64)
    total = 0
    for m in range(movers.size):
        r = movers[m]
        sweep = speed[r] * dt + abs(velocities[r, 2]) * dt * radius[r]
        limit = max(min_width[r] / 2, resolution)
        substeps[m] = max(1, np.int64(math.ceil(sweep / limit)))
        total += substeps[m]
    x, y, heading = np.empty(total), np.empty(total), np.empty(total)
    robot = np.empty(total, dtype=np.int64)
    k = 0
    for m in range(movers.size):
        r = movers[m]
        n = substeps[m]
        for j in range(n):
            fraction = (j + 1) / n
            vx = velocities[r, 0] * fraction * dt
            vy = velocities[r, 1] * fraction * dt
            va = velocities[r, 2] * fraction * dt
            x[k] = poses[r, 0] + vx * cos_a[r] - vy * sin_a[r]
            y[k] = poses[r, 1] + vx * sin_a[r] + vy * cos_a[r]
            heading[k] = normalize(poses[r, 2] + normalize(va))
            robot[k] = r
            k += 1
    return x, y, heading, robot


@numba.njit(inline="always", **_JIT)
def near_layer(x, y, reach, resolution, ox, oy, slots, place, tile_of_slot):
    """Whether a region within ``reach`` metres of (x, y) (a square around it) holds a cell of the tile layer
    (``slots``, ``place``: its grid, whose cell (0, 0) is at (ox, oy); ``tile_of_slot``: the layer's tiles).
    A body farther than its radius from every such region has no point on one of the layer's cells."""
    col0, row0, rcol0, rrow0 = place[0], place[1], place[2], place[3]
    rh, rw = slots.shape
    c_lo = max(0, ((math.floor((x - reach - ox) / resolution) + col0) >> TILE_BITS) - rcol0)
    c_hi = min(rw - 1, ((math.floor((x + reach - ox) / resolution) + col0) >> TILE_BITS) - rcol0)
    r_lo = max(0, ((math.floor((y - reach - oy) / resolution) + row0) >> TILE_BITS) - rrow0)
    r_hi = min(rh - 1, ((math.floor((y + reach - oy) / resolution) + row0) >> TILE_BITS) - rrow0)
    for rr in range(r_lo, r_hi + 1):
        for rc in range(c_lo, c_hi + 1):
            slot = slots[rr, rc]
            if slot >= 0 and tile_of_slot[slot] >= 0:
                return True
    return False


@numba.njit(inline="always", **_JIT)
def _static_hits(points, point_start, point_count, x, y, cos, sin, robot, use, radius, resolution, ox, oy, height,
                 width, slots, place, tile_of_slot, bits, hit, a, b):
    col0, row0, rcol0, rrow0 = place[0], place[1], place[2], place[3]
    rh, rw = slots.shape
    for k in range(a, b):
        r = robot[k]
        if hit[r] or not use[r]:
            continue
        if not near_layer(x[k], y[k], radius[r] + 2 * resolution, resolution, ox, oy, slots, place, tile_of_slot):
            continue  # no point of this probe can fall on a cell of the layer: the reference finds none either
        for i in range(point_start[r], point_start[r] + point_count[r]):
            row, col = point_row_col(x[k], y[k], cos[k], sin[k], points[i, 0], points[i, 1], resolution, ox, oy)
            if not (0 <= col < width and 0 <= row < height):
                continue
            wy, wx = row + row0, col + col0
            rr, rc = (wy >> TILE_BITS) - rrow0, (wx >> TILE_BITS) - rcol0
            if not (0 <= rr < rh and 0 <= rc < rw):
                continue
            slot = slots[rr, rc]
            if slot < 0:
                continue
            tile = tile_of_slot[slot]
            if tile < 0:
                continue
            tx = wx & (TILE - 1)
            if (bits[tile, wy & (TILE - 1), tx >> 3] >> (tx & 7)) & 1:
                hit[r] = True
                break


@numba.njit(**_JIT)
def static_hits(points, point_start, point_count, x, y, cos, sin, robot, use, radius, resolution, ox, oy, height,
                width, slots, place, tile_of_slot, bits, hit):
    """Set ``hit[r]`` for every robot ``r`` whose outline, at one of its probes, falls on a cell of the tile
    layer (``slots``, ``place``: its :class:`~stage_sim.maps.tiles.TileGrid`; ``tile_of_slot``, ``bits``: the
    :class:`~stage_sim.maps.tiles.TileLayer`). Probes of robots with ``use[r]`` false are skipped, and so are
    the points of a probe with no region holding a layer cell within the robot's ``radius`` (:func:`near_layer`)."""
    _static_hits(points, point_start, point_count, x, y, cos, sin, robot, use, radius, resolution, ox, oy, height,
                 width, slots, place, tile_of_slot, bits, hit, 0, x.size)


@numba.njit(parallel=True, **_JIT)
def static_hits_parallel(points, point_start, point_count, x, y, cos, sin, robot, use, radius, resolution, ox, oy,
                         height, width, slots, place, tile_of_slot, bits, hit):
    """:func:`static_hits`, groups of probes on numba's threads (a robot's flag only ever turns True, so the
    order in which its probes are tested changes no answer)."""
    n = x.size
    step = 16
    for k in numba.prange((n + step - 1) // step):
        _static_hits(points, point_start, point_count, x, y, cos, sin, robot, use, radius, resolution, ox, oy,
                     height, width, slots, place, tile_of_slot, bits, hit, k * step, min(n, (k + 1) * step))
