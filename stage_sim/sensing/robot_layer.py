"""Robots as ray obstacles for the numpy caster: an id per cell, and robot-free squares of blocks.

A ray's walk (:mod:`stage_sim.sensing.stage_walk`) hits a robot when it stands in a cell covered by a robot
other than its owner, exactly as it hits a static cell. To let the walk cross robot-free space in one go,
the grid is also cut into blocks of ``2**BLOCK`` cells a side: per block, which robot is there (-1 none,
:data:`SEVERAL_ROBOTS` two or more), and per block and quadrant the largest square of robot-free blocks
ahead of it (:func:`~stage_sim.sensing.distance_field.quadrant_square_fields` on the blocks). The compiled
caster keeps the same layer in :class:`~stage_sim.sensing.fast_caster.RobotCells`.
"""

from __future__ import annotations

import numpy as np

from stage_sim.sensing.distance_field import quadrant_square_fields
from stage_sim.sensing.stage_walk import WalkGrid

#: ``hit_robot`` of a cell covered by two or more robots.
SEVERAL_ROBOTS = -2
#: Robot occupancy blocks: 2**BLOCK cells a side.
BLOCK = 3


def visible_cells(
    cell_rows: np.ndarray, cell_cols: np.ndarray, robot_ids: np.ndarray, shape: tuple[int, int],
    visible: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The (rows, cols, ids) int64 entries that lie on the grid and belong to a visible robot."""
    rows = np.asarray(cell_rows, dtype=np.int64).ravel()
    cols = np.asarray(cell_cols, dtype=np.int64).ravel()
    ids = np.asarray(robot_ids, dtype=np.int64).ravel()
    keep = (rows >= 0) & (rows < shape[0]) & (cols >= 0) & (cols < shape[1]) & (ids >= 0)
    if visible is not None:
        vis = np.asarray(visible, dtype=bool)
        keep &= ids < vis.size
        keep[keep] = vis[ids[keep]]
    return rows[keep], cols[keep], ids[keep]


def _write(target: np.ndarray, flat: np.ndarray, ids: np.ndarray) -> None:
    """Write ``ids`` at ``flat`` of ``target``; a place written by two robots holds :data:`SEVERAL_ROBOTS`."""
    target[flat] = ids
    target[flat[target[flat] != ids]] = SEVERAL_ROBOTS


class RobotLayer:
    """The robots one caster's rays can hit, rebuilt every step (one layer per ray height).

    Each robot covers a set of cells. A ray hits a cell covered by a robot other than its owner; a cell
    covered by two or more robots blocks every ray (they touch there) and is reported as robot
    :data:`SEVERAL_ROBOTS`. Robots not visible at this layer's height (``visible[id]`` false) are left out
    of the cells, not of :attr:`regions` (Stage's regions count every block).
    """

    def __init__(self, shape: tuple[int, int], walk_grid: WalkGrid) -> None:
        self.shape = shape
        self._walk_grid = walk_grid
        self.regions = walk_grid.static_regions
        self.grid = np.full(shape, -1, dtype=np.int32)
        size = 1 << BLOCK
        self.blocks = np.full((-(-shape[0] // size), -(-shape[1] // size)), -1, dtype=np.int32)
        self._blocks_in_use = self.blocks != -1
        self._block_squares = quadrant_square_fields(self._blocks_in_use).ravel()
        self._written = np.empty(0, dtype=np.int64)
        self.active = False

    def update(
        self,
        cell_rows: np.ndarray,
        cell_cols: np.ndarray,
        robot_ids: np.ndarray,
        visible: np.ndarray | None = None,
    ) -> None:
        """Replace the footprints: robot ``robot_ids[i]`` covers cell (``cell_rows[i]``, ``cell_cols[i]``)."""
        self.mark_regions(cell_rows, cell_cols)
        rows, cols, ids = visible_cells(cell_rows, cell_cols, robot_ids, self.shape, visible)
        grid, blocks = self.grid.ravel(), self.blocks.ravel()
        old = self._written
        grid[old] = -1
        blocks[(old // self.shape[1] >> BLOCK) * self.blocks.shape[1] + (old % self.shape[1] >> BLOCK)] = -1
        flat = rows * self.shape[1] + cols
        _write(grid, flat, ids)
        _write(blocks, (rows >> BLOCK) * self.blocks.shape[1] + (cols >> BLOCK), ids)
        in_use = self.blocks != -1
        if not np.array_equal(in_use, self._blocks_in_use):  # standing or jammed robots keep their blocks
            self._blocks_in_use = in_use
            self._block_squares = quadrant_square_fields(in_use).ravel()
        self._written = flat
        self.active = flat.size > 0

    def mark_regions(self, cell_rows: np.ndarray, cell_cols: np.ndarray) -> None:
        """Make the regions of these robot cells non-empty (and only those besides the static ones)."""
        rows, cols, _ = visible_cells(cell_rows, cell_cols, np.zeros(np.size(cell_rows), dtype=np.int64), self.shape,
                                      None)
        self.regions = self._walk_grid.with_cells(rows, cols)

    def look(self, r, c, sx, sy, q, owner) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """For walks standing in grid cells (r, c): (robot hit or -1, free cells ahead along x, along y, and
        whether a robot in the cell's block allows only one plain step)."""
        bh, bw = self.blocks.shape
        bby, bbx = r >> BLOCK, c >> BLOCK
        fy = np.where(sy < 0, bh - 1 - bby, bby)
        fx = np.where(sx < 0, bw - 1 - bbx, bbx)
        side = self._block_squares[(q * bh + fy) * bw + fx].astype(np.int64)
        block = self.blocks[bby, bbx]
        occupied = side == 0
        mine = occupied & ((block == -1) | (block == owner))
        side[mine] = 1
        plain = occupied & ~mine
        rid = np.where(plain, self.grid[r, c], -1).astype(np.int64)
        rid[(rid == owner)] = -1
        kbx = np.where(sx >= 0, ((bbx + side) << BLOCK) - c, c + 1 - ((bbx - side + 1) << BLOCK))
        kby = np.where(sy >= 0, ((bby + side) << BLOCK) - r, r + 1 - ((bby - side + 1) << BLOCK))
        return rid, kbx, kby, plain
