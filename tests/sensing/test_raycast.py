"""The grid ray casters walk as Stage walks (``World::Raytrace``), cell for cell.

The reference is the plain, statement-by-statement port of Stage's walk (:mod:`tests.maps.stage_raytrace`,
every cell visited, no free-space skipping); robots are folded into its grid per ray (every robot cell but
the ray's owner's blocks), and every cell holding a block or a robot makes its region non-empty. The casters
must return the same hit cell and the same range (to 1e-9 m) for every ray. Explicit values check what
Stage reports where it differs from the true ray: whole cells walked from the origin along the major axis.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stage_sim.maps.polygon_raster import fill_polygon
from stage_sim.sensing.robot_layer import SEVERAL_ROBOTS
from tests.maps.stage_raytrace import raytrace, region_grid

RES = 0.05
ORIGIN = (-1.25, 0.75)


def stage_walk(occupied, res, origin, x, y, angle, rmax, blocks=None):
    """Stage's (range, hit cell) of one ray; ``blocks``: the cells that make regions non-empty (default occupied)."""
    col0, row0 = round(origin[0] / res), round(origin[1] / res)
    rows, cols = np.nonzero(occupied if blocks is None else blocks)
    cells = np.stack([cols + col0, rows + row0], axis=1) if rows.size else np.array([[col0, row0]])
    regions, low = region_grid(cells)
    if rows.size == 0:
        regions[:] = False
    walked, cell = raytrace(np.asarray(occupied, dtype=np.bool_), col0, row0, regions, int(low[0]), int(low[1]), x, y,
                            angle, rmax, 1.0 / res)
    return walked, cell


def polygon_cells(polygons, res, origin, shape):
    """(rows, cols, polygon index) of the filled polygons (P, M, 2) or (M, 2), one fill each."""
    polys = np.asarray(polygons, dtype=np.float64)
    polys = polys[None] if polys.ndim == 2 else polys
    cells = [fill_polygon(p, res, origin, shape) for p in polys]
    flat = np.concatenate(cells)
    ids = np.repeat(np.arange(len(cells)), [len(c) for c in cells])
    return flat // shape[1], flat % shape[1], ids


def random_map(rng, h=48, w=64, blocks=35):
    """Rectangles of 1..5 cells plus single cells: thin walls, corners and gaps everywhere."""
    occ = np.zeros((h, w), dtype=bool)
    for _ in range(blocks):
        r, c = rng.integers(0, h), rng.integers(0, w)
        occ[r : r + rng.integers(1, 6), c : c + rng.integers(1, 6)] = True
    occ[rng.random((h, w)) < 0.01] = True
    return occ


def random_rays(rng, occ, n, margin=0.5):
    """Origins anywhere in (and a little around) the grid, any heading, ranges up to the map size."""
    h, w = occ.shape
    xy = np.stack(
        [
            rng.uniform(ORIGIN[0] - margin, ORIGIN[0] + w * RES + margin, n),
            rng.uniform(ORIGIN[1] - margin, ORIGIN[1] + h * RES + margin, n),
        ],
        axis=1,
    )
    return xy, rng.uniform(-2 * math.pi, 2 * math.pi, n), rng.uniform(0.05, 1.2 * w * RES, n)


def assert_matches_traversal(result, occupied, res, origin, xy, angles, rmax, owners=None, robot_grid=None,
                             blocks=None):
    """Every ray: Stage's hit cell, range within 1e-9 m, and the right robot reported. ``blocks``: cells
    that make regions non-empty (default: the static and the robot cells)."""
    rmax = np.broadcast_to(rmax, angles.shape)
    if blocks is None:
        blocks = occupied if robot_grid is None else occupied | (robot_grid != -1)
    for i in range(angles.size):
        occ = occupied
        if robot_grid is not None:
            occ = occupied | ((robot_grid != -1) & (robot_grid != owners[i]))
        want_range, want_cell = stage_walk(occ, res, origin, xy[i, 0], xy[i, 1], angles[i], rmax[i], blocks)
        assert result.hit_cell[i] == want_cell, f"ray {i}: cell {result.hit_cell[i]} != {want_cell}"
        assert abs(result.ranges[i] - want_range) < 1e-9, f"ray {i}: {result.ranges[i]} != {want_range}"
        if robot_grid is not None:
            rid = robot_grid.ravel()[want_cell] if want_cell >= 0 else -1
            want_robot = rid if rid not in (-1, owners[i]) else -1
            assert result.hit_robot[i] == want_robot, f"ray {i}: robot {result.hit_robot[i]} != {want_robot}"


@pytest.mark.parametrize("seed", range(4))
def test_random_rays_match_stages_walk_cell_for_cell(seed, new_caster):
    rng = np.random.default_rng(seed)
    occ = random_map(rng)
    caster = new_caster(occ, RES, ORIGIN)
    xy, angles, rmax = random_rays(rng, occ, 1500)
    result = caster.cast(xy, angles, rmax)
    assert_matches_traversal(result, occ, RES, ORIGIN, xy, angles, rmax)
    assert 0.2 < np.mean(result.hit_cell >= 0) < 0.98  # both hits and misses are exercised


def test_small_and_large_batches_agree(new_caster):
    rng = np.random.default_rng(9)
    occ = random_map(rng, 120, 150, 120)
    caster = new_caster(occ, RES, ORIGIN)
    xy, angles, rmax = random_rays(rng, occ, 20000, margin=0.0)
    big = caster.cast(xy, angles, rmax)
    for a in range(0, 20000, 2500):
        small = caster.cast(xy[a : a + 240], angles[a : a + 240], rmax[a : a + 240])
        np.testing.assert_array_equal(small.hit_cell, big.hit_cell[a : a + 240])
        np.testing.assert_array_equal(small.ranges, big.ranges[a : a + 240])
    pick = rng.choice(20000, 600, replace=False)
    sub = caster.cast(xy[pick], angles[pick], rmax[pick])
    assert_matches_traversal(sub, occ, RES, ORIGIN, xy[pick], angles[pick], rmax[pick])


def test_rays_along_grid_lines_in_all_four_directions(new_caster):
    occ = np.zeros((20, 20), dtype=bool)
    occ[:, 15] = occ[:, 3] = True  # walls at columns 3 and 15
    occ[15, :] = occ[2, :] = True  # and rows 2 and 15
    caster = new_caster(occ, 1.0, (0.0, 0.0))
    # Origin exactly on grid lines (x = 8, y = 9): it belongs to cell (9, 8).
    xy = np.array([[8.0, 9.0]] * 4 + [[8.5, 9.5]] * 4)
    angles = np.array([0.0, math.pi / 2, math.pi, -math.pi / 2] * 2)
    result = caster.cast(xy, angles, 50.0)
    # Stage counts whole cells walked from the origin: towards -x / -y that is one cell more than the true
    # ray's distance to the wall's near face, and an origin inside a cell walks the same whole cells.
    assert result.ranges.tolist() == [7.0, 6.0, 5.0, 7.0] * 2
    assert result.hit_cell.tolist() == [9 * 20 + 15, 15 * 20 + 8, 9 * 20 + 3, 2 * 20 + 8] * 2
    assert_matches_traversal(result, occ, 1.0, (0.0, 0.0), xy, angles, 50.0)


def test_grazing_rays_and_exact_corners(new_caster):
    occ = np.zeros((30, 30), dtype=bool)
    occ[10, 5:25] = True  # a horizontal wall
    occ[20, 20] = True  # a lone cell for corner hits
    caster = new_caster(occ, 0.02, (0.0, 0.0))
    rng = np.random.default_rng(3)
    # Nearly parallel to the wall, just above it: tiny slopes either way.
    n = 400
    xy = np.stack([np.full(n, 0.06), 0.22 + rng.uniform(0, 0.02, n)], axis=1)
    angles = rng.normal(0, 0.02, n)
    # Through exact cell corners (a 45-degree diagonal through corner points, origin on a corner).
    corners = np.array([[0.2, 0.2], [0.3, 0.3], [0.38, 0.38], [0.4, 0.42]])
    xy = np.vstack([xy, corners, corners])
    angles = np.concatenate([angles, np.full(4, math.pi / 4), np.full(4, -3 * math.pi / 4)])
    result = caster.cast(xy, angles, 1.0)
    assert_matches_traversal(result, occ, 0.02, (0.0, 0.0), xy, angles, 1.0)


def test_origin_inside_an_obstacle_gives_zero(new_caster):
    occ = np.zeros((10, 10), dtype=bool)
    occ[4, 4] = True
    caster = new_caster(occ, 0.1, (0.0, 0.0))
    result = caster.cast([[0.45, 0.45], [0.4, 0.4]], [1.0, -2.0], 5.0)
    assert list(result.ranges) == [0.0, 0.0]
    assert list(result.hit_cell) == [44, 44]


def test_misses_return_the_max_range_exactly(new_caster):
    occ = np.zeros((10, 10), dtype=bool)
    occ[5, 9] = True
    caster = new_caster(occ, 0.1, (0.0, 0.0))
    rmax = np.array([0.3, 2.0 / 3.0, 50.0, 0.35])
    # Short range before the wall; leaving the map; the wall is exactly 0.4 m away.
    result = caster.cast([[0.5, 0.55], [0.5, 0.55], [0.5, 0.55], [0.5, 0.55]], [0.0, math.pi, 2.0, 0.0], rmax)
    np.testing.assert_array_equal(result.ranges, rmax)
    np.testing.assert_array_equal(result.hit_cell, [-1, -1, -1, -1])
    # Stage's walk takes int(range / resolution) steps and does not look at the cell its last step reaches:
    # the wall 4 cells away is seen with a range of 5 cells, not with 4.1.
    assert caster.cast([[0.5, 0.55]], [0.0], 0.41).ranges[0] == 0.41
    assert caster.cast([[0.5, 0.55]], [0.0], 0.5).ranges[0] == pytest.approx(0.4, abs=1e-12)


def test_origins_outside_the_grid_enter_it(new_caster):
    occ = np.zeros((10, 10), dtype=bool)
    occ[:, 5] = True
    caster = new_caster(occ, 1.0, (0.0, 0.0))
    result = caster.cast([[-3.5, 2.5], [12.0, 7.2], [-3.0, -3.0]], [0.0, math.pi, math.pi / 4], 20.0)
    assert result.ranges[:2] == pytest.approx([8.5, 7.0], abs=1e-12)  # Stage: to the far side from +x
    assert_matches_traversal(
        result,
        occ,
        1.0,
        (0.0, 0.0),
        np.array([[-3.5, 2.5], [12.0, 7.2], [-3.0, -3.0]]),
        np.array([0.0, math.pi, math.pi / 4]),
        20.0,
    )


def test_angles_beyond_pi_wrap(new_caster):
    rng = np.random.default_rng(2)
    occ = random_map(rng)
    caster = new_caster(occ, RES, ORIGIN)
    xy, angles, rmax = random_rays(rng, occ, 300, margin=0.0)
    base = caster.cast(xy, angles, rmax)
    for turns in (-2, 1, 3):
        turned = caster.cast(xy, angles + 2 * math.pi * turns, rmax)
        np.testing.assert_allclose(turned.ranges, base.ranges, atol=1e-9)
        assert np.mean(turned.hit_cell == base.hit_cell) > 0.99  # cos/sin of θ+2πk round differently
        assert_matches_traversal(turned, occ, RES, ORIGIN, xy, angles + 2 * math.pi * turns, rmax)


def test_two_heights_see_their_own_layers(new_caster):
    low = np.zeros((20, 20), dtype=bool)
    low[:, 8] = True  # a low box: only the low layer has it
    high = np.zeros((20, 20), dtype=bool)
    high[:, 14] = True  # a wall seen by both
    low |= high
    casters = {0.1: new_caster(low, 0.1, (0.0, 0.0)), 0.3: new_caster(high, 0.1, (0.0, 0.0))}
    xy = np.array([[0.25, 1.05]] * 2)
    ranges = {z: c.cast(xy, [0.0, 0.0], 5.0).ranges[0] for z, c in casters.items()}
    # Whole cells walked from x = 2.5 cells (Stage's range; the true ray meets the faces 0.05 m sooner).
    assert ranges[0.1] == pytest.approx(0.6, abs=1e-12)
    assert ranges[0.3] == pytest.approx(1.2, abs=1e-12)


def _robot_world(new_caster):
    occ = np.zeros((40, 60), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    caster = new_caster(occ, 0.05, (0.0, 0.0))
    squares = np.array(
        [
            [[x - 0.2, y - 0.2], [x + 0.2, y - 0.2], [x + 0.2, y + 0.2], [x - 0.2, y + 0.2]]
            for x, y in ((0.6, 1.0), (1.6, 1.0), (2.4, 1.0), (1.6, 1.6))
        ]
    )
    rows, cols, ids = polygon_cells(squares, 0.05, (0.0, 0.0), occ.shape)
    return occ, caster, rows, cols, ids


def test_robot_layer_hits_other_robots_and_passes_through_its_own(new_caster):
    occ, caster, rows, cols, ids = _robot_world(new_caster)
    layer = caster.robot_layer()
    layer.update(rows, cols, ids)
    xy = np.array([[0.6, 1.0], [1.6, 1.0], [1.6, 1.0], [0.6, 1.0]])
    angles = np.array([0.0, math.pi, math.pi / 2, math.pi])
    owners = np.array([0, 1, 1, 0])
    result = caster.cast(xy, angles, 10.0, owners=owners, robots=layer)
    assert result.hit_robot.tolist() == [1, 0, 3, -1]
    assert result.ranges[0] == pytest.approx(1.6 - 0.2 - 0.6, abs=1e-9)  # robot 1's near face
    assert result.ranges[3] == pytest.approx(0.6, abs=1e-9)  # through itself to the wall (its far side: Stage)
    grid = np.full(occ.shape, -1)
    grid[rows, cols] = ids
    assert_matches_traversal(result, occ, 0.05, (0.0, 0.0), xy, angles, 10.0, owners, grid)


def test_robot_layer_invisible_robots_shared_cells_and_random_rays(new_caster):
    occ, caster, rows, cols, ids = _robot_world(new_caster)
    layer = caster.robot_layer()
    visible = np.array([True, False, True, True])
    # Robot 3 also claims a cell of robot 2: that shared cell blocks everybody.
    shared = (rows[ids == 2][0], cols[ids == 2][0])
    rows, cols, ids = np.append(rows, shared[0]), np.append(cols, shared[1]), np.append(ids, 3)
    layer.update(rows, cols, ids, visible)
    grid = np.full(occ.shape, -1)
    for r, c, i in zip(rows, cols, ids, strict=True):
        if visible[i]:
            grid[r, c] = i if grid[r, c] in (-1, i) else SEVERAL_ROBOTS
    rng = np.random.default_rng(4)
    n = 1200
    owners = rng.integers(-1, 4, n)
    centres = np.array([[0.6, 1.0], [1.6, 1.0], [2.4, 1.0], [1.6, 1.6], [0.3, 0.3]])
    xy = centres[owners] + rng.normal(0, 0.05, (n, 2))
    angles = rng.uniform(-math.pi, math.pi, n)
    result = caster.cast(xy, angles, 4.0, owners=owners, robots=layer)
    blocks = occ.copy()
    blocks[rows, cols] = True  # invisible robots' blocks count for the regions too
    assert_matches_traversal(result, occ, 0.05, (0.0, 0.0), xy, angles, 4.0, owners, grid, blocks)
    assert not np.any(result.hit_robot == 1)  # invisible at this height
    assert np.any(result.hit_robot == SEVERAL_ROBOTS)
    # Moving robots: the next update replaces the old footprints completely.
    layer.update(rows[ids == 0], cols[ids == 0], ids[ids == 0])
    again = caster.cast(xy, angles, 4.0, owners=owners, robots=layer)
    assert set(np.unique(again.hit_robot)) <= {-1, 0}


def test_polygon_cells_fills_centres_and_keeps_thin_bodies():
    square = np.array([[0.12, 0.12], [0.48, 0.12], [0.48, 0.28], [0.12, 0.28]])
    rows, cols, poly = polygon_cells(square, 0.1, (0.0, 0.0), (10, 10))
    assert set(zip(rows.tolist(), cols.tolist(), strict=True)) == {(r, c) for r in (1, 2) for c in (1, 2, 3, 4)}
    assert np.all(poly == 0)
    # A sliver thinner than a cell, at an angle: every cell it crosses, and a connected chain.
    sliver = np.array([[0.05, 0.12], [0.95, 0.58], [0.95, 0.585], [0.05, 0.125]])
    rows, cols, _ = polygon_cells(sliver, 0.1, (0.0, 0.0), (10, 10))
    assert len(rows) >= 10 and set(cols.tolist()) == set(range(10))
    # Batched, concave (an L), clipped to the grid.
    ell = np.array([[0.0, 0.0], [0.4, 0.0], [0.4, 0.1], [0.1, 0.1], [0.1, 0.4], [0.0, 0.4]])
    far = ell + 0.85
    rows, cols, poly = polygon_cells(np.stack([ell, far]), 0.1, (0.0, 0.0), (10, 10))
    cells0 = set(zip(rows[poly == 0].tolist(), cols[poly == 0].tolist(), strict=True))
    assert (0, 0) in cells0 and (0, 3) in cells0 and (3, 0) in cells0 and (2, 2) not in cells0
    assert np.all(rows[poly == 1] <= 9) and (8, 8) in set(
        zip(rows[poly == 1].tolist(), cols[poly == 1].tolist(), strict=True)
    )
