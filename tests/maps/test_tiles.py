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


@pytest.mark.parametrize("seed", range(6))
def test_a_grid_and_layer_extended_with_more_cells_are_those_built_from_all_of_them(seed: int) -> None:
    """An episode's world adds bodies to its base: the base's tile grid and layers are extended
    (``TileGrid.with_blocks``, ``TileLayer.with_cells``), slot for slot and tile for tile what building them
    from every cell gives, also when the new cells fall in new regions, in regions already held, or in none."""
    rng = np.random.default_rng(seed)
    shape = (int(rng.integers(40, 400)), int(rng.integers(40, 400)))
    base = np.unique(rng.integers(0, shape[0] * shape[1], int(rng.integers(0, 600))))
    more = rng.integers(0, shape[0] * shape[1], int(rng.integers(0, 300)))
    if seed == 0:
        more = base[:5]  # no new region
    origin = (float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5)))
    grid = TileGrid.build(shape, 0.05, origin, base)
    extended = grid.with_blocks(more)
    fresh = TileGrid.build(shape, 0.05, origin, np.concatenate([base, more]))
    np.testing.assert_array_equal(extended.slots, fresh.slots)
    assert (extended.col0, extended.row0, extended.rcol0, extended.rrow0) == (fresh.col0, fresh.row0, fresh.rcol0,
                                                                              fresh.rrow0)
    layer_cells = base[rng.random(base.size) < 0.5]
    layer = TileLayer.from_cells(grid, layer_cells).with_cells(extended, more)
    expected = TileLayer.from_cells(fresh, np.unique(np.concatenate([layer_cells, more])))
    np.testing.assert_array_equal(layer.tile_of_slot, expected.tile_of_slot)
    np.testing.assert_array_equal(layer.bits, expected.bits)


def test_an_episode_world_extends_its_base_tiles_into_those_of_a_fresh_raster() -> None:
    """``with_models`` (an episode's obstacles) extends the base raster's grid and layers: the same arrays as a
    raster built from all the bodies."""
    from stage_sim.maps.raster import StaticRaster, with_models
    from stage_sim.worldfile.loader import load_world_text as load

    base_text = ("resolution 0.05\nmodel( size [8 0.1 1] pose [0 -3 0 0] obstacle_return 1 )\n"
                 "model( size [0.1 6 0.5] pose [3.9 0 0 0] obstacle_return 1 )\n")
    base = build_static_raster(load(base_text, "base.world"))
    base.collision_tiles(0.0, 0.4), base.sensing_tiles(0.2)  # made, as a simulation of the base world makes them
    boxes = load(base_text + "model( size [0.6 0.4 1] pose [1 1 0 30] obstacle_return 1 )\n"
                 "model( size [0.3 0.9 0.3] pose [-2 0.5 0 70] obstacle_return 1 )\n", "boxes.world").models[2:]
    episode = with_models(base, boxes)
    assert episode is not None and episode.extends is base
    fresh = StaticRaster(episode.shape, episode.resolution, episode.origin_xy, episode.bodies)
    np.testing.assert_array_equal(episode.grid.slots, fresh.grid.slots)
    for extended, built in ((episode.collision_tiles(0.0, 0.4), fresh.collision_tiles(0.0, 0.4)),
                            (episode.sensing_tiles(0.2)[0], fresh.sensing_tiles(0.2)[0])):
        np.testing.assert_array_equal(extended.tile_of_slot, built.tile_of_slot)
        np.testing.assert_array_equal(extended.bits, built.bits)


def test_an_episode_world_that_grows_the_grid_moves_the_filled_footprints_it_had() -> None:
    """A box reaching past the base grid grows it: the base bodies' outlines and the filled footprints already
    made move onto the new grid (the same world cells a fill on the new grid gives), not filled again."""
    from dataclasses import replace

    from stage_sim.maps.raster import with_models
    from stage_sim.worldfile.loader import load_world_text as load

    base_text = ("resolution 0.05\nmodel( size [8 0.1 1] pose [0 -3 0 0] obstacle_return 1 )\n"
                 "model( size [0.1 6 0.5] pose [3.9 0 0 0] obstacle_return 1 )\n")
    base = build_static_raster(load(base_text, "base.world"))
    base.filled_collision_layer(0.0, 0.4)  # what placement asks of the base world
    boxes = load(base_text + "model( size [0.9 0.9 1] pose [4.1 2.5 0 30] obstacle_return 1 )\n",
                 "boxes.world").models[2:]
    episode = with_models(base, boxes)
    assert episode.shape[1] > base.shape[1] and episode.extends is None
    for moved in episode.bodies[:2]:
        assert "cells" in moved.__dict__
        np.testing.assert_array_equal(moved.cells, replace(moved).cells)  # a copy fills its own
    fresh = np.zeros(episode.shape, dtype=bool)
    for body in episode.bodies:
        fresh.ravel()[replace(body).cells] = True
    np.testing.assert_array_equal(episode.filled_collision_layer(0.0, 0.4), fresh)


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
