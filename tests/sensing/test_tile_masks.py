"""The tables the compiled walk reads of a static layer: per tile, row masks, column masks and which rows and
columns hold a cell, each bit the cell the layer's tiles hold."""

from __future__ import annotations

import numpy as np

from stage_sim.maps.tiles import TILE, TileGrid, TileLayer
from stage_sim.sensing.fast_caster import bit_masks


def test_masks_hold_the_layers_cells_bit_for_bit() -> None:
    rng = np.random.default_rng(11)
    shape = (150, 230)
    for density in (0.001, 0.05, 0.5, 1.0):
        flat = np.flatnonzero(rng.random(shape[0] * shape[1]) < density)
        grid = TileGrid.build(shape, 0.05, (-0.8, 1.35), flat)
        layer = TileLayer.from_cells(grid, flat)
        rows, cols, rows_used, cols_used = bit_masks(layer)
        occupied = layer.occupied  # (T, TILE, TILE) [tile, row, col]
        bit = np.uint32(1) << np.arange(TILE, dtype=np.uint32)
        assert rows.dtype == cols.dtype == rows_used.dtype == cols_used.dtype == np.uint32
        np.testing.assert_array_equal((rows[:, :, None] & bit) != 0, occupied)
        np.testing.assert_array_equal((cols[:, :, None] & bit) != 0, occupied.transpose(0, 2, 1))
        np.testing.assert_array_equal((rows_used[:, None] & bit) != 0, occupied.any(axis=2))
        np.testing.assert_array_equal((cols_used[:, None] & bit) != 0, occupied.any(axis=1))
