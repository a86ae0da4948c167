"""The compiled region labelling numbers the regions exactly as scipy.ndimage.label does."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from stage_sim.envs.region_kernels import label8

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
