"""The sparse static world: cells kept in tiles where something is, dense copies only for small worlds."""

from __future__ import annotations

import numpy as np
import pytest

from stage_sim import load_world_text
from stage_sim.maps.raster import build_static_raster
from stage_sim.maps.tiles import DENSE_CELL_LIMIT, TILE, CellValues, TileGrid, TileLayer, WorldTooLargeError


def test_a_layer_holds_exactly_its_cells_in_the_tiles_of_their_regions() -> None:
    rng = np.random.default_rng(3)
    shape = (300, 500)
    cells = np.unique(rng.integers(0, shape[0] * shape[1], 2000))
    grid = TileGrid.build(shape, 0.05, (-3.0, 1.05), cells)  # the grid starts 60 / 21 cells off world cell 0
    layer = TileLayer.from_cells(grid, cells[::2])
    np.testing.assert_array_equal(layer.cells(), cells[::2])
    probe = np.concatenate([cells, [-1]])
    expected = np.isin(probe, cells[::2])
    np.testing.assert_array_equal(layer.contains(probe), expected)
    # a region (32 x 32 world cells, aligned on world cell 0) gets a tile only where the layer has a cell
    rows, cols = np.divmod(cells[::2], shape[1])
    regions = {((r + 21) // TILE, (c - 60) // TILE) for r, c in zip(rows, cols, strict=True)}
    assert layer.bits.shape[0] == len(regions)


def test_intensities_are_the_last_body_s_and_a_single_value_stores_no_cells() -> None:
    values = CellValues.last_wins(np.array([7, 3, 7, 9]), np.array([0.5, 1.0, 2.0, 1.0]))
    np.testing.assert_array_equal(values.at(np.array([3, 7, 9])), [1.0, 2.0, 1.0])
    uniform = CellValues.last_wins(np.array([7, 3, 9]), np.full(3, 0.5))
    assert uniform.cells.size == 0
    np.testing.assert_array_equal(uniform.at(np.array([3, 9])), [0.5, 0.5])


HUGE_WORLD = """
resolution 0.01
model( name "wall" size [200 0.5 1] pose [100 0.25 0 0] )
model( name "box" size [2 2 1] pose [150 150 0 0] )
"""


def test_a_huge_world_refuses_a_dense_map_and_gives_a_downsampled_picture() -> None:
    raster = build_static_raster(load_world_text(HUGE_WORLD, "huge.world"))
    height, width = raster.shape
    assert height * width > DENSE_CELL_LIMIT
    with pytest.raises(WorldTooLargeError, match=rf"{width} x {height} cells"):
        raster.to_occupancy_grid()
    labels, step = raster.map_labels()
    assert step > 1 and labels.size <= DENSE_CELL_LIMIT
    box_row, box_col = (np.array([150.0, 150.0]) - np.array(raster.origin_xy[::-1])) / raster.resolution
    assert labels[int(box_row - 100) // step, int(box_col) // step] == 2  # the middle of the box's south edge
    assert labels[0, labels.shape[1] // 2] == 1  # the wall along y = 0
    assert (labels == 0).mean() > 0.9
