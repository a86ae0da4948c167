"""Compiled (numba) update of a :class:`~stage_sim.sensing.robot_layer.RobotLayer`: the numpy update's result,
in one pass over the robots' cells (no temporaries the size of the cells but the per-cell tile numbers).

Only the row and column masks, the used-line masks and the owner are cleared each step (268 B a tile): a
cell's id is read only where its mask bit is set, so the ids (4 KB a tile, tens of MB for robots drawn at
1 mm) are written, never wiped."""

from __future__ import annotations

import numba
import numpy as np

from stage_sim.maps.tiles import TILE, TILE_BITS

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(**_JIT)
def number_robot_regions(regions, marked, marked_count, cells, ids, visible, place, width, marked_value):
    """Clear the regions marked last time (the first ``marked_count[0]`` of ``marked``), mark the regions of the
    flat grid cells (−1: off the grid) with ``marked_value`` and list them in ``marked`` (their count in
    ``marked_count[0]``; room for every region, each is listed once), and number the regions of the visible
    ones 0, 1, … in the order met. The marked regions stay in the caller's arrays: a returned array would cost
    each step's caller some 0.7 µs to receive.

    Returns (per cell its tile or -1, per cell its row · TILE + col in the tile, tiles)."""
    col0, row0, rcol0, rrow0 = place[0], place[1], place[2], place[3]
    flat_regions = regions.ravel()
    rw = regions.shape[1]
    for k in range(marked_count[0]):
        flat_regions[marked[k]] = -1
    n = cells.size
    tile = np.full(n, -1, dtype=np.int32)
    local = np.zeros(n, dtype=np.int32)
    m = 0
    count = 0
    per_width = 1.0 / width
    for i in range(n):
        cell = cells[i]
        if cell < 0:
            continue
        if i > 0 and cell == cells[i - 1] and ids[i] == ids[i - 1]:  # the cell before's (a vertex shared by
            tile[i], local[i] = tile[i - 1], local[i - 1]  # two edges, or two blocks): nothing new to mark
            continue
        r = np.int64(cell * per_width)  # cell // width without an integer division, corrected to be exact
        if r * width > cell:
            r -= 1
        elif (r + 1) * width <= cell:
            r += 1
        wy, wx = r + row0, cell - r * width + col0
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
    marked_count[0] = m
    return tile, local, count


@numba.njit(**_JIT)
def write_robot_tiles(cell_ids, rows, cols, rows_used, cols_used, owner, tile, local, ids, count, several):
    """Clear the masks of tiles 0…count-1, then write robot ``ids[i]`` into its cell (``several`` where two
    robots meet), its bit into the row and column masks, its row and column into the tile's ``rows_used``
    and ``cols_used`` masks, and its id into ``owner`` (``several`` once a tile holds two robots' cells);
    returns whether any cell was written."""
    rows[:count] = 0
    cols[:count] = 0
    rows_used[:count] = 0
    cols_used[:count] = 0
    owner[:count] = -1
    written = False
    for i in range(tile.size):
        t = tile[i]
        if t < 0:
            continue
        written = True
        if i > 0 and t == tile[i - 1] and local[i] == local[i - 1] and ids[i] == ids[i - 1]:
            continue  # the point before's cell, written already
        robot = ids[i]
        y, x = local[i] >> TILE_BITS, local[i] & (TILE - 1)
        bit = np.uint32(1) << np.uint32(x)
        if rows[t, y] & bit == 0:  # the first robot in this cell this step
            cell_ids[t, y, x] = robot
            rows[t, y] |= bit
            cols[t, x] |= np.uint32(1) << np.uint32(y)
            rows_used[t] |= np.uint32(1) << np.uint32(y)
            cols_used[t] |= bit
            if owner[t] != robot:
                owner[t] = robot if owner[t] == -1 else several
        elif cell_ids[t, y, x] != robot:  # (the cell's first robot is the tile's, or it has several)
            cell_ids[t, y, x] = several
            owner[t] = several
    return written
