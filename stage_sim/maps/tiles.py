"""The static world stored sparsely: 32 × 32-cell tiles where something is, nothing where nothing is.

The world grid (the bounding box of the static models and the robots' start discs, ``H × W`` cells at the
world ``resolution``) is never allocated. It is cut into Stage's regions of :data:`TILE` × :data:`TILE`
cells, aligned on world cell 0 (Stage's ``RBITS = 5``; the ray walk jumps over regions without a block,
:mod:`stage_sim.sensing.stage_walk`), and only the regions that hold a static block cell get a *slot*.
Every layer of cells (what rays see at one height, what blocks one z band) keeps one tile per slot in
which it has a cell. Flat cell indices stay those of the virtual ``H × W`` grid (``row · W + col``), so a
cell means the same thing everywhere.

What it costs:

* :class:`TileGrid` — the slot index, int32 per region: 4 B per 1024 cells of the bounding box
  (a 1 km × 1 km world at 0.01 m: 9.8 M regions, 39 MB; 30 m × 30 m at 0.001 m: 3.5 MB);
* :class:`TileLayer` — 4 B per slot (which tile) plus 128 B per tile (a bit per cell);
* :class:`CellValues` — 12 B per cell it holds (sorted int64 cell, float32 value), nothing when every cell
  holds the same value.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: Cells per tile side: Stage's regions (``RBITS = 5``).
TILE_BITS = 5
TILE = 1 << TILE_BITS
#: Largest virtual grid a dense copy (a picture, ``/map``, a distance transform) is made of.
DENSE_CELL_LIMIT = 64_000_000


def unique_sorted(values: np.ndarray) -> np.ndarray:
    """Sorted distinct integers of ``values``: ``np.unique`` by a sort (numpy 2.4's hashing ``np.unique``
    is some 50 times slower on the million-cell outlines of a large floorplan)."""
    ordered = np.sort(np.asarray(values).ravel())
    keep = np.ones(ordered.size, dtype=bool)
    keep[1:] = ordered[1:] != ordered[:-1]
    return ordered[keep]


class WorldTooLargeError(ValueError):
    """A whole-world dense copy was asked of a world too large to hold one."""


@dataclass(frozen=True)
class TileGrid:
    """Where the virtual grid lies in Stage's world cells, its regions, and which regions hold a static block."""

    shape: tuple[int, int]  #: (H, W) cells of the virtual grid
    col0: int  #: world cell column of the grid's column 0
    row0: int  #: world cell row of the grid's row 0
    rcol0: int  #: region column of the region grid's column 0
    rrow0: int
    slots: np.ndarray  #: (R, C) int32: slot of each region holding a static block, −1 for none

    @classmethod
    def build(cls, shape: tuple[int, int], resolution: float, origin_xy: tuple[float, float],
              blocks: np.ndarray) -> TileGrid:
        """The grid of ``shape`` placed at ``origin_xy`` (snapped to a cell), ``blocks`` its flat block cells."""
        col0 = round(origin_xy[0] / resolution)
        row0 = round(origin_xy[1] / resolution)
        h, w = shape
        rcol0, rrow0 = col0 >> TILE_BITS, row0 >> TILE_BITS
        regions = (((row0 + h - 1) >> TILE_BITS) - rrow0 + 1, ((col0 + w - 1) >> TILE_BITS) - rcol0 + 1)
        slots = np.full(regions, -1, dtype=np.int32)
        grid = cls((int(h), int(w)), col0, row0, rcol0, rrow0, slots)
        rr, rc, _, _ = grid.locate(np.asarray(blocks, dtype=np.int64))
        used = unique_sorted(rr * regions[1] + rc)
        slots.ravel()[used] = np.arange(used.size, dtype=np.int32)
        return grid

    def with_blocks(self, blocks: np.ndarray) -> TileGrid:
        """This grid with more flat block cells ``blocks`` (all on it): what :meth:`build` makes of this grid's
        blocks and those, the slots numbered alike (in region order), from the regions alone."""
        rr, rc, _, _ = self.locate(np.asarray(blocks, dtype=np.int64))
        held = self.slots.ravel()
        used = np.union1d(np.flatnonzero(held >= 0), rr * self.slots.shape[1] + rc)
        if used.size == self.slot_count:
            return self
        slots = np.full(self.slots.shape, -1, dtype=np.int32)
        slots.ravel()[used] = np.arange(used.size, dtype=np.int32)
        return TileGrid(self.shape, self.col0, self.row0, self.rcol0, self.rrow0, slots)

    @property
    def slot_count(self) -> int:
        return int(self.slots.max(initial=-1)) + 1

    @property
    def place(self) -> np.ndarray:
        """(col0, row0, rcol0, rrow0) as the kernels take them."""
        return np.array([self.col0, self.row0, self.rcol0, self.rrow0], dtype=np.int64)

    def locate(self, flat: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(region row, region col, row in tile, col in tile) of flat grid cells (all on the grid)."""
        wy, wx = np.divmod(flat, self.shape[1])
        wy += self.row0
        wx += self.col0
        return (wy >> TILE_BITS) - self.rrow0, (wx >> TILE_BITS) - self.rcol0, wy & (TILE - 1), wx & (TILE - 1)

    def check_dense(self, what: str) -> None:
        """Refuse, with the reason, a whole-world dense copy of a grid over :data:`DENSE_CELL_LIMIT` cells."""
        h, w = self.shape
        if h * w > DENSE_CELL_LIMIT:
            raise WorldTooLargeError(
                f"{what} needs the whole world as one picture, and this world is {w} x {h} cells "
                f"({h * w / 1e6:.0f} M; the limit is {DENSE_CELL_LIMIT / 1e6:.0f} M): use a coarser resolution")


@dataclass(frozen=True)
class TileLayer:
    """A set of cells of a :class:`TileGrid`: a tile of bits for each slot the set has a cell in."""

    grid: TileGrid
    tile_of_slot: np.ndarray  #: (S,) int32: the layer's tile of each slot, −1 where it has no cell
    bits: np.ndarray  #: (T, TILE, TILE / 8) uint8, [tile, row in tile, col in tile / 8], bit col % 8
    derived: dict = field(default_factory=dict, compare=False, repr=False)
    """What users compute from the layer once for all (the casters' free squares and bit masks)."""

    @classmethod
    def from_cells(cls, grid: TileGrid, flat: np.ndarray) -> TileLayer:
        """The layer of flat grid cells ``flat`` (every one in a region holding a block of ``grid``)."""
        rr, rc, ty, tx = grid.locate(np.asarray(flat, dtype=np.int64))
        slot = grid.slots[rr, rc]
        used = unique_sorted(slot)
        tile = np.searchsorted(used, slot)
        tile_of_slot = np.full(grid.slot_count, -1, dtype=np.int32)
        tile_of_slot[used] = np.arange(used.size, dtype=np.int32)
        occupied = np.zeros((used.size, TILE, TILE), dtype=bool)
        occupied[tile, ty, tx] = True
        return cls(grid, tile_of_slot, np.packbits(occupied, axis=-1, bitorder="little"))

    def with_cells(self, grid: TileGrid, flat: np.ndarray) -> TileLayer:
        """The layer of this one's cells and the flat cells ``flat`` on ``grid``, this layer's grid with more
        blocks (:meth:`TileGrid.with_blocks`): what :meth:`from_cells` makes of them all, this layer's tiles
        moved to their new places rather than made again."""
        rr, rc, ty, tx = grid.locate(np.asarray(flat, dtype=np.int64))
        slot = grid.slots[rr, rc]
        old = np.flatnonzero(self.tile_of_slot >= 0)  # this layer's slots, in its tiles' order
        regions = np.flatnonzero(self.grid.slots.ravel() >= 0)  # this grid's regions, in its slots' order
        moved = grid.slots.ravel()[regions[old]]
        used = np.union1d(moved, slot)
        tile_of_slot = np.full(grid.slot_count, -1, dtype=np.int32)
        tile_of_slot[used] = np.arange(used.size, dtype=np.int32)
        bits = np.zeros((used.size, TILE, TILE // 8), dtype=np.uint8)
        bits[tile_of_slot[moved]] = self.bits[self.tile_of_slot[old]]
        np.bitwise_or.at(bits, (tile_of_slot[slot], ty, tx >> 3), (1 << (tx & 7)).astype(np.uint8))
        return TileLayer(grid, tile_of_slot, bits)

    @property
    def occupied(self) -> np.ndarray:
        """(T, TILE, TILE) bool: the tiles unpacked, [tile, row in tile, col in tile]."""
        return np.unpackbits(self.bits, axis=-1, bitorder="little").astype(bool)

    def contains(self, flat: np.ndarray) -> np.ndarray:
        """Whether each flat grid cell is in the layer (−1, off the grid, is not)."""
        flat = np.asarray(flat, dtype=np.int64)
        out = np.zeros(flat.shape, dtype=bool)
        on = flat >= 0
        rr, rc, ty, tx = self.grid.locate(flat[on])
        slot = self.grid.slots[rr, rc]
        tile = np.full(slot.shape, -1, dtype=np.int64)
        tile[slot >= 0] = self.tile_of_slot[slot[slot >= 0]]
        found = tile >= 0
        hits = np.zeros(tile.shape, dtype=bool)
        hits[found] = (self.bits[tile[found], ty[found], tx[found] >> 3] >> (tx[found] & 7)) & 1
        out[on] = hits
        return out

    def cells(self) -> np.ndarray:
        """Sorted flat grid cells of the layer."""
        slot_regions = np.flatnonzero(self.grid.slots.ravel() >= 0)
        region_of_slot = np.empty(slot_regions.size, dtype=np.int64)
        region_of_slot[self.grid.slots.ravel()[slot_regions]] = slot_regions
        slot_of_tile = np.empty(self.occupied.shape[0], dtype=np.int64)
        used = np.flatnonzero(self.tile_of_slot >= 0)
        slot_of_tile[self.tile_of_slot[used]] = used
        tile, ty, tx = np.nonzero(self.occupied)
        rr, rc = np.divmod(region_of_slot[slot_of_tile[tile]], self.grid.slots.shape[1])
        rows = ((rr + self.grid.rrow0) << TILE_BITS) + ty - self.grid.row0
        cols = ((rc + self.grid.rcol0) << TILE_BITS) + tx - self.grid.col0
        return np.sort(rows * self.grid.shape[1] + cols)

    def dense(self, what: str = "a dense copy of a layer") -> np.ndarray:
        """The layer as an (H, W) bool grid, for worlds under :data:`DENSE_CELL_LIMIT` cells."""
        self.grid.check_dense(what)
        out = np.zeros(self.grid.shape[0] * self.grid.shape[1], dtype=bool)
        out[self.cells()] = True
        return out.reshape(self.grid.shape)


@dataclass(frozen=True)
class CellValues:
    """A value for each of a set of flat cells (the intensity of the cells a ray can hit)."""

    cells: np.ndarray  #: sorted unique int64 flat cells (empty when every cell holds ``values[0]``)
    values: np.ndarray  #: float32, one per cell (one for all)

    @classmethod
    def last_wins(cls, flat: np.ndarray, values: np.ndarray) -> CellValues:
        """Cells with their value, the last entry of a cell listed twice winning (as a painter's overwrite)."""
        values = np.asarray(values, dtype=np.float32)
        if values.size == 0 or np.all(values == values[0]):
            return cls(np.zeros(0, dtype=np.int64), values[:1])
        flat = np.asarray(flat, dtype=np.int64)
        order = np.argsort(flat, kind="stable")
        flat, values = flat[order], values[order]
        last = np.ones(flat.size, dtype=bool)
        last[:-1] = flat[1:] != flat[:-1]
        return cls(flat[last], values[last])

    def at(self, flat: np.ndarray) -> np.ndarray:
        """The value of each of the flat cells ``flat``, every one of them in the set (a ray's static hit)."""
        flat = np.asarray(flat, dtype=np.int64)
        if self.cells.size == 0:
            return np.full(flat.shape, self.values[0] if self.values.size else 0.0, dtype=np.float32)
        return self.values[np.searchsorted(self.cells, flat)]
