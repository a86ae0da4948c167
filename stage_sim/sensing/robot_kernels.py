"""Compiled (numba) update of a :class:`~stage_sim.sensing.robot_layer.RobotLayer`: the numpy update's result,
in one pass over the robots' cells (no temporaries the size of the cells but the per-cell tile numbers)."""

from __future__ import annotations

import numba
import numpy as np

from stage_sim.maps.tiles import TILE, TILE_BITS

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(**_JIT)
def number_robot_regions(regions, old, cells, ids, visible, place, width, marked_value):
    """Clear the regions marked last time (``old``), mark the regions of the flat grid cells (−1: off the
    grid) with ``marked_value``, and number the regions of the visible ones 0, 1, … in the order met.

    Returns (regions marked now, per cell its tile or -1, per cell its row · TILE + col in the tile, tiles)."""
    col0, row0, rcol0, rrow0 = place[0], place[1], place[2], place[3]
    flat_regions = regions.ravel()
    rw = regions.shape[1]
    for f in old:
        flat_regions[f] = -1
    n = cells.size
    marked = np.empty(n, dtype=np.int64)
    tile = np.full(n, -1, dtype=np.int32)
    local = np.zeros(n, dtype=np.int32)
    m = 0
    count = 0
    for i in range(n):
        if cells[i] < 0:
            continue
        r, c = cells[i] // width, cells[i] % width
        wy, wx = r + row0, c + col0
        region = ((wy >> TILE_BITS) - rrow0) * rw + (wx >> TILE_BITS) - rcol0
        if flat_regions[region] == -1:
            flat_regions[region] = marked_value
            marked[m] = region
            m += 1
        robot = ids[i]
        if robot >= 0 and robot < visible.size and visible[robot]:
            if flat_regions[region] < 0:
                flat_regions[region] = count
                count += 1
            tile[i] = flat_regions[region]
            local[i] = ((wy & (TILE - 1)) << TILE_BITS) + (wx & (TILE - 1))
    return marked[:m], tile, local, count


@numba.njit(**_JIT)
def write_robot_tiles(cell_ids, rows, cols, tile, local, ids, count, several):
    """Clear tiles 0…count-1, then write robot ``ids[i]`` into its cell (``several`` where two robots meet)
    and its bit into the row and column masks; returns whether any cell was written."""
    cell_ids[:count] = -1
    rows[:count] = 0
    cols[:count] = 0
    written = False
    for i in range(tile.size):
        t = tile[i]
        if t < 0:
            continue
        written = True
        robot = ids[i]
        y, x = local[i] >> TILE_BITS, local[i] & (TILE - 1)
        seen = cell_ids[t, y, x]
        cell_ids[t, y, x] = robot if seen == -1 or seen == robot else several
        rows[t, y] |= np.uint32(1) << np.uint32(x)
        cols[t, x] |= np.uint32(1) << np.uint32(y)
    return written
