"""Robots as ray obstacles: an id per cell in tiles allocated where robots are, and what lets a walk cross them.

A ray's walk (:mod:`stage_sim.sensing.stage_walk`) hits a robot when it stands in a cell covered by a robot
other than its owner, exactly as it hits a static cell. Robot cells live in tiles of the world's regions
(:mod:`stage_sim.maps.tiles`), allocated each step for the regions the visible robots' cells fall in. To
let the walk cross robot-free space in one go, each caster gets what it reads besides the ids:

* the numpy caster: a tile cut into blocks of ``2**BLOCK`` cells a side: per block, which robot is there
  (-1 none, :data:`SEVERAL_ROBOTS` two or more), and per block and quadrant the largest square of robot-free
  blocks ahead of it within the tile (:func:`~stage_sim.sensing.distance_field.tile_square_fields`);
* the compiled caster: a 32-bit mask of the robot cells of every row and every column of a tile
  (:mod:`stage_sim.sensing.traversal` tests a whole run of its walk against one), per tile a mask of the
  rows and one of the columns holding a robot cell (the walk crosses the others many runs at a time), and
  the tile's one robot (:data:`SEVERAL_ROBOTS` if more): a ray of that robot walks the tile as if empty of
  robots, as a robot's own cells never stop its rays (a ray leaves its robot's body through such tiles).

What it costs: the region index, int32 per region (4 B per 1024 cells of the world's bounding box; the
compiled layer also keeps room to list every region it marks, int64 per region); per tile in use 4 KB of ids
(int32 per cell) and 128 B of block owners and squares (numpy) or 268 B of masks and owner (compiled). Each
update touches only the cells the robots cover (O(robot cells), no sort).
"""

from __future__ import annotations

import numpy as np

from stage_sim.maps.tiles import TILE, TileGrid
from stage_sim.sensing.distance_field import tile_square_fields
from stage_sim.sensing.stage_walk import BLOCK

#: ``hit_robot`` of a cell covered by two or more robots.
SEVERAL_ROBOTS = -2
#: Blocks per tile side.
TILE_BLOCKS = TILE >> BLOCK
#: :attr:`RobotLayer.regions` of a region holding robot cells none of which this layer sees.
MARKED = -2


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


def _write(target: np.ndarray, index: tuple, ids: np.ndarray) -> None:
    """Write ``ids`` at ``index`` of ``target``; a place written by two robots holds :data:`SEVERAL_ROBOTS`."""
    target[index] = ids
    clash = target[index] != ids
    target[tuple(i[clash] for i in index)] = SEVERAL_ROBOTS


class RobotLayer:
    """The robots one caster's rays can hit, rebuilt every step (one layer per ray height).

    Each robot covers a set of cells. A ray hits a cell covered by a robot other than its owner; a cell
    covered by two or more robots blocks every ray (they touch there) and is reported as robot
    :data:`SEVERAL_ROBOTS`. Robots not visible at this layer's height (``visible[id]`` false) are left out
    of the cells, not of :attr:`regions` (Stage's regions count every block). What the numpy caster reads
    (:class:`CompiledRobotLayer`: what the compiled one reads).
    """

    def __init__(self, grid: TileGrid) -> None:
        self.grid = grid
        self._place = grid.place
        self.shape = grid.shape
        #: (R, C) int32 per region: its robot tile, :data:`MARKED`, or -1 (no robot cell there)
        self.regions = np.full(grid.slots.shape, -1, dtype=np.int32)
        self.ids = np.full((0, TILE, TILE), -1, dtype=np.int32)  #: (T, 32, 32) robot id per cell
        self.blocks = np.full((0, TILE_BLOCKS, TILE_BLOCKS), -1, dtype=np.int32)  #: robot per 8 × 8 block
        self.block_squares = np.zeros((0, 4, TILE_BLOCKS, TILE_BLOCKS), dtype=np.uint8)
        self._marked = np.empty(0, dtype=np.int64)
        self.active = False

    @property
    def marked(self) -> np.ndarray:
        """The regions holding robot cells (flat in the region grid): where :attr:`regions` is not -1."""
        return self._marked

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
        rr, rc, ty, tx = self.grid.locate(rows * self.shape[1] + cols)
        region = rr * self.regions.shape[1] + rc
        flat_regions = self.regions.ravel()
        # Number the regions without sorting: each region keeps the last entry written to it, then the
        # entries that won are numbered in order.
        flat_regions[region] = np.arange(region.size, dtype=np.int32)
        winner = flat_regions[region]
        first = np.zeros(region.size, dtype=bool)
        first[winner] = True
        number = np.cumsum(first, dtype=np.int32) - 1
        tile = number[winner]
        flat_regions[region] = tile
        count = int(first.sum())
        self.reserve(count)
        self.ids[:count] = -1
        self.blocks[:count] = -1
        _write(self.ids, (tile, ty, tx), ids.astype(np.int32))
        _write(self.blocks, (tile, ty >> BLOCK, tx >> BLOCK), ids.astype(np.int32))
        self.block_squares = tile_square_fields(self.blocks[:count] != -1)
        self.active = rows.size > 0

    def update_flat(self, cells: np.ndarray, robot_ids: np.ndarray, visible: np.ndarray | None = None) -> None:
        """:meth:`update` with flat grid cells (−1: off the grid), as the simulation places bodies."""
        self.update(*self._rows_cols(cells), robot_ids, visible)

    def _flat(self, cell_rows: np.ndarray, cell_cols: np.ndarray) -> np.ndarray:
        """Flat grid cells of (row, col) pairs, −1 for those off the grid."""
        rows = np.asarray(cell_rows, dtype=np.int64).ravel()
        cols = np.asarray(cell_cols, dtype=np.int64).ravel()
        on = (rows >= 0) & (rows < self.shape[0]) & (cols >= 0) & (cols < self.shape[1])
        return np.where(on, rows * self.shape[1] + cols, -1)

    def _rows_cols(self, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(rows, cols) of flat grid cells, (−1, −1) for −1."""
        cells = np.asarray(cells, dtype=np.int64).ravel()
        rows, cols = np.divmod(cells, self.shape[1])
        off = cells < 0
        rows[off] = cols[off] = -1
        return rows, cols

    @property
    def capacity(self) -> int:
        """Tiles the layer has room for."""
        return self.ids.shape[0]

    def reserve(self, count: int) -> None:
        """Room for ``count`` tiles (grown by doubling, never shrunk: robots come back)."""
        if count > self.ids.shape[0]:
            capacity = max(count, 2 * self.ids.shape[0])
            self.ids = np.empty((capacity, TILE, TILE), dtype=np.int32)
            self._grow(capacity)

    def _grow(self, capacity: int) -> None:
        """Room for ``capacity`` tiles in what the caster reads besides the ids."""
        self.blocks = np.empty((capacity, TILE_BLOCKS, TILE_BLOCKS), dtype=np.int32)

    def mark_regions(self, cell_rows: np.ndarray, cell_cols: np.ndarray) -> None:
        """Make the regions of these robot cells non-empty (and only those besides the static ones)."""
        flat_regions = self.regions.ravel()
        flat_regions[self._marked] = -1
        rows, cols, _ = visible_cells(cell_rows, cell_cols, np.zeros(np.size(cell_rows), dtype=np.int64), self.shape,
                                      None)
        rr, rc, _, _ = self.grid.locate(rows * self.shape[1] + cols)
        self._marked = rr * self.regions.shape[1] + rc
        flat_regions[self._marked] = MARKED

    def mark_flat(self, cells: np.ndarray) -> None:
        """:meth:`mark_regions` with flat grid cells (−1: off the grid)."""
        self.mark_regions(*self._rows_cols(cells))

    def look(self, tile, cy, cx, sx, sy, q, owner) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """For walks standing in cell (cy, cx) of robot tile ``tile`` (≥ 0): (robot hit or -1, free cells ahead
        along x, along y, and whether a robot in the cell's block allows only one plain step)."""
        bby, bbx = cy >> BLOCK, cx >> BLOCK
        side = self.block_squares[tile, q, bby, bbx].astype(np.int64)
        block = self.blocks[tile, bby, bbx]
        occupied = side == 0
        mine = occupied & ((block == -1) | (block == owner))
        side[mine] = 1
        plain = occupied & ~mine
        rid = np.where(plain, self.ids[tile, cy, cx], -1).astype(np.int64)
        rid[(rid == owner)] = -1
        kbx = np.where(sx >= 0, ((bbx + side) << BLOCK) - cx, cx + 1 - ((bbx - side + 1) << BLOCK))
        kby = np.where(sy >= 0, ((bby + side) << BLOCK) - cy, cy + 1 - ((bby - side + 1) << BLOCK))
        return rid, kbx, kby, plain


class CompiledRobotLayer(RobotLayer):
    """:class:`RobotLayer` as the compiled caster reads it (row and column masks, used lines, owner per tile),
    updated with the numba kernels (:mod:`stage_sim.sensing.robot_kernels`, imported on first use); the same
    cells, ids and regions as the reference's."""

    def __init__(self, grid: TileGrid) -> None:
        # Whether the layer holds a cell, and the regions marked (the first ``marked_count[0]``), kept in arrays
        # that the kernels update in place: a fused step (sim/fused_kernels.py) updates this layer with no
        # answer to hand back.
        self.active_flag = np.zeros(1, dtype=np.bool_)
        self.marked_count = np.zeros(1, dtype=np.int64)
        super().__init__(grid)
        self.marked_regions = np.empty(self.regions.size, dtype=np.int64)
        self.rows = np.zeros((0, TILE), dtype=np.uint32)  #: (T, 32) robot cells of each row
        self.cols = np.zeros((0, TILE), dtype=np.uint32)  #: (T, 32) robot cells of each column
        self.rows_used = np.zeros(0, dtype=np.uint32)  #: (T,) rows of a tile holding a robot cell
        self.cols_used = np.zeros(0, dtype=np.uint32)  #: (T,) columns of a tile holding one
        self.owner = np.zeros(0, dtype=np.int32)  #: (T,) the tile's one robot, or SEVERAL_ROBOTS

    def update(self, cell_rows: np.ndarray, cell_cols: np.ndarray, robot_ids: np.ndarray,
               visible: np.ndarray | None = None) -> None:
        self.update_flat(self._flat(cell_rows, cell_cols), robot_ids, visible)

    def update_flat(self, cells: np.ndarray, robot_ids: np.ndarray, visible: np.ndarray | None = None) -> None:
        from stage_sim.sensing import robot_kernels

        ids = np.asarray(robot_ids, dtype=np.int64).ravel()
        seen = np.ones(int(ids.max(initial=-1)) + 1, dtype=bool) if visible is None else np.asarray(visible, bool)
        tile, local, count = robot_kernels.number_robot_regions(
            self.regions, self.marked_regions, self.marked_count, np.asarray(cells, dtype=np.int64).ravel(), ids,
            seen, self._place, self.shape[1], MARKED)
        self.reserve(count)
        self.active = robot_kernels.write_robot_tiles(self.ids, self.rows, self.cols, self.rows_used, self.cols_used,
                                                      self.owner, tile, local, ids.astype(np.int32), count,
                                                      SEVERAL_ROBOTS)

    @property
    def marked(self) -> np.ndarray:
        return self.marked_regions[:self.marked_count[0]]

    @property
    def active(self) -> bool:
        """Whether the layer holds a robot cell (what the walk reads)."""
        return bool(self.active_flag[0])

    @active.setter
    def active(self, value: bool) -> None:
        self.active_flag[0] = value

    @property
    def tables(self) -> tuple[np.ndarray, ...]:
        """What the compiled walk reads: (regions, ids, row masks, column masks, used rows, used columns, owner)."""
        return self.regions, self.ids, self.rows, self.cols, self.rows_used, self.cols_used, self.owner

    def _grow(self, capacity: int) -> None:
        self.rows = np.empty((capacity, TILE), dtype=np.uint32)
        self.cols = np.empty((capacity, TILE), dtype=np.uint32)
        self.rows_used = np.empty(capacity, dtype=np.uint32)
        self.cols_used = np.empty(capacity, dtype=np.uint32)
        self.owner = np.empty(capacity, dtype=np.int32)

    def mark_regions(self, cell_rows: np.ndarray, cell_cols: np.ndarray) -> None:
        self.mark_flat(self._flat(cell_rows, cell_cols))

    def mark_flat(self, cells: np.ndarray) -> None:
        from stage_sim.sensing import robot_kernels  # the compiled numbering, with no robot seen: marks only

        cells = np.asarray(cells, dtype=np.int64).ravel()
        robot_kernels.number_robot_regions(
            self.regions, self.marked_regions, self.marked_count, cells, np.zeros(cells.size, dtype=np.int64),
            np.zeros(1, dtype=bool), self._place, self.shape[1], MARKED)
