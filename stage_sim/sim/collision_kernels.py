"""Compiled (numba) inner loops of :mod:`stage_sim.sim.collision`, with the numpy code's arithmetic exactly.

The trigonometry stays in numpy (the caller passes each pose's cos and sin, computed by the same numpy
calls as the reference), so the cells below are the reference's cells bit for bit.
"""

from __future__ import annotations

import math

import numba

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(**_JIT)
def body_cells(points, pose_index, x, y, cos, sin, resolution, ox, oy, height, width, out):
    """Flat cell (or -1 off the grid) of body point i placed at pose ``pose_index[i]``; the numpy
    reference is ``point_cells(place(points, poses[pose_index]))``."""
    for i in range(points.shape[0]):
        p = pose_index[i]
        px = points[i, 0]
        py = points[i, 1]
        wx = x[p] + cos[p] * px - sin[p] * py
        wy = y[p] + sin[p] * px + cos[p] * py
        col = math.floor((wx - ox) / resolution)
        row = math.floor((wy - oy) / resolution)
        out[i] = row * width + col if 0 <= col < width and 0 <= row < height else -1


@numba.njit(**_JIT)
def owner_clashes(cells, owner, grid, conflict):
    """Mark robots sharing a cell: write every owner into its cells (the last write stays), read back,
    flag both robots of any mismatch, then clear ``grid`` to -1 again."""
    for i in range(cells.size):
        if cells[i] >= 0:
            grid[cells[i]] = owner[i]
    for i in range(cells.size):
        if cells[i] >= 0:
            seen = grid[cells[i]]
            if seen != owner[i]:
                conflict[owner[i]] = True
                conflict[seen] = True
    for i in range(cells.size):
        if cells[i] >= 0:
            grid[cells[i]] = -1
