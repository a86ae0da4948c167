"""Exactness of the vectorised grid ray caster against two independent references.

* ``traverse``: a plain per-cell Amanatides–Woo walk in pure Python with the formulas of the module
  docstring (crossing times computed fresh, minor axis first on ties). The caster must return the
  same hit cell and the same distance (to 1e-9 m) for every ray.
* ``sample``: brute force, no grid-line arithmetic at all: points every ``step`` << cell along the
  ray, each mapped to its cell; the entry into the first occupied sample's cell is then solved for
  exactly. A sampler can step over a cell that the ray only clips near a corner (when one step
  crosses a vertical and a horizontal grid line); such rays are detected, counted and required to
  be rare, all others must agree to 1e-6 m.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stage_sim.maps.polygon_raster import fill_polygon
from stage_sim.sensing.robot_layer import SEVERAL_ROBOTS

RES = 0.05
ORIGIN = (-1.25, 0.75)


def traverse(occupied, res, origin, x, y, angle, rmax):
    """Reference traversal; ``occupied(row, col)`` says whether a cell blocks. Returns (range, cell)."""
    h, w = occupied.shape if hasattr(occupied, "shape") else occupied.grid_shape
    is_occ = occupied.__getitem__ if hasattr(occupied, "shape") else occupied
    u = (x - origin[0]) / res
    v = (y - origin[1]) / res
    dx = math.cos(angle) + 0.0
    dy = math.sin(angle) + 0.0
    idx = 1.0 / dx if dx != 0 else math.inf
    idy = 1.0 / dy if dy != 0 else math.inf
    x_major = abs(dx) >= abs(dy)
    sx = 1 if dx >= 0 else -1
    sy = 1 if dy >= 0 else -1
    ix, iy = math.floor(u), math.floor(v)
    t = 0.0
    while True:
        if 0 <= ix < w and 0 <= iy < h and is_occ((iy, ix)):
            return t * res, iy * w + ix
        tx = ((ix + (sx > 0)) - u) * idx
        ty = ((iy + (sy > 0)) - v) * idy
        if (tx < ty) if x_major else (tx <= ty):
            t, ix = tx, ix + sx
        else:
            t, iy = ty, iy + sy
        if t >= rmax / res:
            return rmax, -1


def sample(occ, res, origin, x, y, angle, rmax, step):
    """Brute-force (range, cell, clipped_corner) by sampling; see the module docstring."""
    h, w = occ.shape
    dx, dy = math.cos(angle), math.sin(angle)
    t = np.arange(0.0, rmax, step)
    col = np.floor((x + t * dx - origin[0]) / res).astype(np.int64)
    row = np.floor((y + t * dy - origin[1]) / res).astype(np.int64)
    inside = (col >= 0) & (col < w) & (row >= 0) & (row < h)
    blocked = np.zeros(t.size, dtype=bool)
    blocked[inside] = occ[row[inside], col[inside]]
    # A step that changes both the row and the column skips the cell between them: if that cell is
    # occupied (and the sampler did not stop before), the sampler is provably wrong there.
    both = np.flatnonzero((np.diff(col) != 0) & (np.diff(row) != 0))
    hits = np.flatnonzero(blocked)
    first = hits[0] if hits.size else t.size
    for i in both[both < first]:
        for r, c in ((row[i], col[i + 1]), (row[i + 1], col[i])):
            if 0 <= r < h and 0 <= c < w and occ[r, c]:
                return None, None, True
    if not hits.size:
        return rmax, -1, False
    if first == 0:
        return 0.0, row[0] * w + col[0], False
    # Entry into the hit cell: through the grid line between the previous sample's cell and it.
    if col[first] != col[first - 1]:
        line = max(col[first], col[first - 1])
        entry = (origin[0] + line * res - x) / dx
    else:
        line = max(row[first], row[first - 1])
        entry = (origin[1] + line * res - y) / dy
    return entry, row[first] * w + col[first], False


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


def assert_matches_traversal(result, occupied, res, origin, xy, angles, rmax, owners=None, robot_grid=None):
    """Every ray: same hit cell, range within 1e-9 m, and the right robot reported."""
    rmax = np.broadcast_to(rmax, angles.shape)
    for i in range(angles.size):
        occ_fn = occupied
        if robot_grid is not None:
            own = owners[i]

            class _Occ:
                grid_shape = occupied.shape

                def __call__(self, rc, own=own):
                    rid = robot_grid[rc]
                    return occupied[rc] or (rid != -1 and rid != own)

            occ_fn = _Occ()
        want_range, want_cell = traverse(occ_fn, res, origin, xy[i, 0], xy[i, 1], angles[i], rmax[i])
        assert result.hit_cell[i] == want_cell, f"ray {i}: cell {result.hit_cell[i]} != {want_cell}"
        assert abs(result.ranges[i] - want_range) < 1e-9, f"ray {i}: {result.ranges[i]} != {want_range}"
        if robot_grid is not None:
            rid = robot_grid.ravel()[want_cell] if want_cell >= 0 else -1
            want_robot = rid if rid not in (-1, owners[i]) else -1
            assert result.hit_robot[i] == want_robot, f"ray {i}: robot {result.hit_robot[i]} != {want_robot}"


@pytest.mark.parametrize("seed", range(4))
def test_random_rays_match_the_traversal_cell_for_cell(seed, new_caster):
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


def test_brute_force_sampling_agrees_except_on_provably_skipped_corners(new_caster):
    rng = np.random.default_rng(5)
    occ = random_map(rng)
    caster = new_caster(occ, RES, ORIGIN)
    xy, angles, rmax = random_rays(rng, occ, 400, margin=0.0)
    result = caster.cast(xy, angles, rmax)
    skipped = 0
    for i in range(angles.size):
        want, cell, clipped = sample(occ, RES, ORIGIN, xy[i, 0], xy[i, 1], angles[i], rmax[i], RES / 64)
        if clipped:
            skipped += 1
            continue
        if cell == -1:
            assert result.hit_cell[i] == -1 and result.ranges[i] == rmax[i]
            continue
        assert result.hit_cell[i] == cell, f"ray {i}"
        assert abs(result.ranges[i] - want) < 1e-6, f"ray {i}: {result.ranges[i]} vs {want}"
    assert skipped <= angles.size // 50, f"{skipped} corner-clipped rays"


def test_rays_along_grid_lines_in_all_four_directions(new_caster):
    occ = np.zeros((20, 20), dtype=bool)
    occ[:, 15] = occ[:, 3] = True  # walls at columns 3 and 15
    occ[15, :] = occ[2, :] = True  # and rows 2 and 15
    caster = new_caster(occ, 1.0, (0.0, 0.0))
    # Origin exactly on grid lines (x = 8, y = 9): it belongs to cell (9, 8).
    xy = np.array([[8.0, 9.0]] * 4 + [[8.5, 9.5]] * 4)
    angles = np.array([0.0, math.pi / 2, math.pi, -math.pi / 2] * 2)
    result = caster.cast(xy, angles, 50.0)
    assert result.ranges[0] == 7.0 and result.hit_cell[0] == 9 * 20 + 15
    assert result.ranges[1] == pytest.approx(6.0, abs=1e-12) and result.hit_cell[1] == 15 * 20 + 8
    assert result.ranges[2] == pytest.approx(4.0, abs=1e-12) and result.hit_cell[2] == 9 * 20 + 3
    assert result.ranges[3] == pytest.approx(6.0, abs=1e-12) and result.hit_cell[3] == 2 * 20 + 8
    assert result.ranges[4:] == pytest.approx([6.5, 5.5, 4.5, 6.5], abs=1e-12)
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
    assert caster.cast([[0.5, 0.55]], [0.0], 0.41).ranges[0] == pytest.approx(0.4, abs=1e-12)


def test_origins_outside_the_grid_enter_it(new_caster):
    occ = np.zeros((10, 10), dtype=bool)
    occ[:, 5] = True
    caster = new_caster(occ, 1.0, (0.0, 0.0))
    result = caster.cast([[-3.5, 2.5], [12.0, 7.2], [-3.0, -3.0]], [0.0, math.pi, math.pi / 4], 20.0)
    assert result.ranges[:2] == pytest.approx([8.5, 6.0], abs=1e-12)
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
    assert ranges[0.1] == pytest.approx(0.55, abs=1e-12)
    assert ranges[0.3] == pytest.approx(1.15, abs=1e-12)


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
    assert result.ranges[3] == pytest.approx(0.6 - 0.05, abs=1e-9)  # through itself to the wall
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
    assert_matches_traversal(result, occ, 0.05, (0.0, 0.0), xy, angles, 4.0, owners, grid)
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
