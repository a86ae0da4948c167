"""The compiled region labelling numbers the regions exactly as scipy.ndimage.label does."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from stage_sim.envs.free_space_kernels import clear_near, label8

EIGHT = np.ones((3, 3), dtype=bool)


@pytest.mark.parametrize("density", [0.2, 0.45, 0.6, 0.9])
def test_random_grids_get_scipys_labels(density: float) -> None:
    rng = np.random.default_rng(int(density * 100))
    for _ in range(40):
        shape = tuple(rng.integers(1, 60, 2))
        valid = rng.random(shape) < density
        labels, count = label8(valid)
        expected, expected_count = ndimage.label(valid, structure=EIGHT)
        assert count == expected_count and labels.dtype == expected.dtype
        np.testing.assert_array_equal(labels, expected)


def test_spirals_and_diagonals_merge_late_as_in_scipy() -> None:
    valid = np.zeros((40, 40), dtype=bool)
    for k in range(0, 40, 4):  # combs joined at the bottom row: many provisional labels, one region
        valid[:, k] = True
    valid[-1, :] = True
    np.fill_diagonal(valid[:20, 20:], True)  # a diagonal touching the combs only at corners
    valid[5, 30:] = True
    for grid in (valid, valid[::-1], valid[:, ::-1], ~valid, np.zeros((3, 4), bool), np.ones((1, 1), bool)):
        labels, count = label8(grid)
        expected, expected_count = ndimage.label(grid, structure=EIGHT)
        assert count == expected_count
        np.testing.assert_array_equal(labels, expected)


def _disk(reach: float, resolution: float) -> np.ndarray:
    """The rows (row offset, first and last column offset) of the cells within ``reach`` of a cell, by the
    distances a distance transform computes."""
    pad = int(reach / resolution) + 1
    rows, cols = np.mgrid[-pad:pad + 1, -pad:pad + 1]
    near = ~(np.sqrt((rows * rows + cols * cols).astype(np.float64)) * resolution > reach)
    return np.array([(r, cols[i][near[i]].min(), cols[i][near[i]].max()) for i, r in enumerate(rows[:, 0])
                     if near[i].any()], dtype=np.int64)


@pytest.mark.parametrize("reach", [0.05, 0.349, 0.35, 0.6])
def test_cells_near_new_bodies_are_those_a_distance_transform_finds(reach: float) -> None:
    rng = np.random.default_rng(int(reach * 1000))
    resolution = 0.05
    spans = _disk(reach, resolution)
    for _ in range(30):
        added = np.zeros(tuple(rng.integers(5, 70, 2)), dtype=bool)
        for _ in range(rng.integers(1, 4)):  # solid blocks (deep inner cells), some at the grid's edge
            r, c = rng.integers(-5, added.shape[0]), rng.integers(-5, added.shape[1])
            added[max(r, 0):r + rng.integers(1, 30), max(c, 0):c + rng.integers(1, 30)] = True
        added |= rng.random(added.shape) < 0.01
        valid = rng.random(added.shape) < 0.9
        expected = valid & (ndimage.distance_transform_edt(~added) * resolution > reach)
        clear_near(valid, added, spans)
        np.testing.assert_array_equal(valid, expected)


@pytest.mark.parametrize("resolution", [0.05, 0.037])
def test_compiled_footprints_are_the_bodies_filled_cells(resolution: float) -> None:
    """An episode's new bodies are marked blocked by the compiled fill (``add_bodies``): the very cells of
    ``StaticBody.cells`` (outline and centres inside, even-odd), for boxes, concave and self-crossing polygons,
    bodies of several polygons, and bodies partly off the grid; each body's box holds its cells, and the valid
    centres lost are those near the cells it newly blocks, reported sorted."""
    from stage_sim.envs.free_space_kernels import add_bodies
    from stage_sim.maps.raster import StaticBody

    rng = np.random.default_rng(int(resolution * 1000))
    shape, origin = (90, 120), (-1.013, -0.71)
    extent = np.array([shape[1], shape[0]]) * resolution
    for trial in range(150):
        polygons = []
        for _ in range(int(rng.integers(1, 3))):
            centre = np.array(origin) + rng.uniform(-0.2, 1.2, 2) * extent
            if rng.random() < 0.5:  # a rotated box, as the obstacles scenario draws
                (sx, sy), yaw = rng.uniform(0.05, 1.5, 2), rng.uniform(-np.pi, np.pi)
                corners = np.array([[-sx, -sy], [sx, -sy], [sx, sy], [-sx, sy]]) / 2
                rotation = np.array([[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]])
                polygons.append(centre + corners @ rotation.T)
            else:  # any polygon: concave, self-crossing, with horizontal edges on cell centres
                points = centre + rng.uniform(-1.0, 1.0, (int(rng.integers(3, 9)), 2))
                points[0, 1] = points[1, 1] = origin[1] + (int(rng.integers(0, shape[0])) + 0.5) * resolution
                polygons.append(points)
        outline = np.unique(rng.integers(0, shape[0] * shape[1], 20))
        body = StaticBody("b", outline, (0.0, 1.0), 1.0, True, polygons, (resolution, origin, shape))
        expected = np.zeros(shape, dtype=bool)
        expected.ravel()[body.cells] = True
        marked = rng.random(shape) < 0.02  # cells blocked before: not new, drawing no disk of their own
        before = marked.copy()
        spans = _disk((0.06, 0.35, 0.61)[trial % 3], resolution)
        valid = rng.random(shape) < 0.9
        clear_near(valid, before, spans)  # a free space: nothing valid near a blocked cell
        start = valid.copy()
        reference = valid.copy()
        clear_near(reference, expected | before, spans)
        lost, boxes = add_bodies(marked, valid, [body], spans)
        np.testing.assert_array_equal(marked, expected | before)
        np.testing.assert_array_equal(valid, reference)
        np.testing.assert_array_equal(lost, np.flatnonzero(start & ~valid))
        rows, cols = np.nonzero(expected)
        assert boxes.tolist() == [[rows.min(), rows.max() + 1, cols.min(), cols.max() + 1]]
