"""The numba caster returns exactly (bit for bit) what the numpy reference returns, on any thread count."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stage_sim.sensing import stop_map
from stage_sim.sensing.casters import make_caster
from stage_sim.sensing.distance_field import tile_square_fields
from stage_sim.sensing.robot_layer import SEVERAL_ROBOTS

RES = 0.02
ORIGIN = (-3.01, 1.7)


def office(rng: np.random.Generator, h: int = 260, w: int = 330) -> np.ndarray:
    """Walls on grid lines, doors, scattered boxes and single cells: big enough for the 64-cell blocks."""
    occ = np.zeros((h, w), dtype=bool)
    occ[[0, -1], :] = occ[:, [0, -1]] = True
    for y in range(0, h, 70):
        occ[y : y + 2, :] = True
        for door in rng.integers(5, w - 20, 3):
            occ[y : y + 2, door : door + 15] = False
    for x in range(0, w, 90):
        occ[:, x] = True
        for door in rng.integers(5, h - 20, 2):
            occ[door : door + 15, x] = False
    for _ in range(60):
        r, c = rng.integers(0, h), rng.integers(0, w)
        occ[r : r + rng.integers(1, 9), c : c + rng.integers(1, 9)] = True
    occ[rng.random((h, w)) < 0.002] = True
    return occ


def rays(rng: np.random.Generator, occ: np.ndarray, scans: int, beams: int):
    """Scans of ``beams`` rays over 270°, from anywhere (also outside the grid and on grid lines/corners)."""
    h, w = occ.shape
    xy = np.stack([rng.uniform(-0.3, w * RES + 0.3, scans), rng.uniform(-0.3, h * RES + 0.3, scans)], axis=1)
    on_lines = rng.random(scans) < 0.3
    xy[on_lines] = np.round(xy[on_lines] / RES) * RES  # cell corners (the origin is a multiple of RES too)
    xy += np.array(ORIGIN)
    heading = rng.uniform(-math.pi, math.pi, scans)
    aligned = rng.random(scans) < 0.3
    heading[aligned] = rng.integers(-4, 4, aligned.sum()) * (math.pi / 4)  # axis and diagonal beams
    angles = heading[:, None] + np.linspace(-0.75 * math.pi, 0.75 * math.pi, beams)[None, :]
    reach = rng.choice([0.3, 5.6, 30.0], scans)
    return np.repeat(xy, beams, axis=0), angles.ravel(), np.repeat(reach, beams)


def crowd(rng: np.random.Generator, occ: np.ndarray, robots: int):
    """Robots as 9 × 11-cell boxes, many touching or overlapping their neighbours (shared cells)."""
    h, w = occ.shape
    rows, cols, ids = [], [], []
    centre = np.array([h / 2, w / 2])
    for i in range(robots):
        r0, c0 = (centre + rng.normal(0, 12, 2)).astype(int)
        rr, cc = np.mgrid[r0 : r0 + 9, c0 : c0 + 11]
        rows.append(rr.ravel())
        cols.append(cc.ravel())
        ids.append(np.full(rr.size, i))
    return tuple(np.concatenate(a) for a in (rows, cols, ids))


def assert_identical(a, b) -> None:
    np.testing.assert_array_equal(a.hit_cell, b.hit_cell)
    np.testing.assert_array_equal(a.hit_robot, b.hit_robot)
    assert a.ranges.tobytes() == b.ranges.tobytes()


@pytest.mark.parametrize("seed", range(3))
def test_static_map_identical_on_random_offices(seed):
    rng = np.random.default_rng(seed)
    occ = office(rng)
    xy, angles, reach = rays(rng, occ, 60, 181)
    numpy_result = make_caster(occ, RES, ORIGIN, "numpy").cast(xy, angles, reach)
    numba_result = make_caster(occ, RES, ORIGIN, "numba").cast(xy, angles, reach)
    assert_identical(numba_result, numpy_result)
    hits = numpy_result.hit_cell >= 0
    assert 0.3 < hits.mean() < 0.99 and np.any(numpy_result.ranges == 0.0)


def test_grazing_rays_along_walls_identical():
    occ = np.zeros((200, 400), dtype=bool)
    occ[100, 20:380] = True
    occ[40:160, 300] = True
    rng = np.random.default_rng(11)
    n = 3000
    xy = np.stack([np.full(n, 0.5), 2.0 + rng.uniform(-0.05, 0.05, n)], axis=1) + np.array(ORIGIN)
    angles = np.concatenate([rng.normal(0, 1e-3, n - 8), [0.0, math.pi, 1e-17, -1e-17, math.pi / 2, -math.pi / 2,
                                                           math.pi / 4, 3 * math.pi / 4]])
    numpy_result = make_caster(occ, RES, ORIGIN, "numpy").cast(xy, angles, 8.0)
    numba_result = make_caster(occ, RES, ORIGIN, "numba").cast(xy, angles, 8.0)
    assert_identical(numba_result, numpy_result)


def scattered_segments(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    """A few short walls, 1-2 cells thick, along either axis, and lone cells: tiles with a wall in them are
    mostly empty rows and columns, which the compiled walk crosses a band at a time."""
    occ = np.zeros((h, w), dtype=bool)
    for _ in range(rng.integers(3, 40)):
        r, c, length, thick = rng.integers(0, h), rng.integers(0, w), rng.integers(1, 60), rng.integers(1, 3)
        if rng.random() < 0.5:
            occ[r : r + thick, c : c + length] = True
        else:
            occ[r : r + length, c : c + thick] = True
    occ[rng.random((h, w)) < rng.uniform(0.0, 0.0005)] = True
    return occ


@pytest.mark.parametrize("seed", range(40))
def test_rays_across_mostly_empty_tiles_identical(seed):
    """Rays from anywhere (cell corners too), every direction (axes and multiples of 22.5° too), ending
    anywhere (within a tile's empty band, on a wall, beyond): the band crossing changes no answer."""
    rng = np.random.default_rng(100 + seed)
    h, w = rng.integers(40, 300, 2)
    occ = scattered_segments(rng, h, w)
    blocks = occ | (rng.random((h, w)) < 0.0003)  # regions holding a block at another height only
    n = 2000
    xy = np.stack([rng.uniform(-0.3, w * RES + 0.3, n), rng.uniform(-0.3, h * RES + 0.3, n)], axis=1)
    on_lines = rng.random(n) < 0.3
    xy[on_lines] = np.round(xy[on_lines] / RES) * RES
    xy += np.array(ORIGIN)
    angles = rng.uniform(-math.pi, math.pi, n)
    aligned = rng.random(n) < 0.2
    angles[aligned] = rng.integers(-8, 8, aligned.sum()) * (math.pi / 8)
    reach = rng.uniform(0.0, 8.0, n)
    numpy_result = make_caster(occ, RES, ORIGIN, "numpy", blocks=blocks).cast(xy, angles, reach)
    numba_result = make_caster(occ, RES, ORIGIN, "numba", blocks=blocks).cast(xy, angles, reach)
    assert_identical(numba_result, numpy_result)
    assert np.any(numpy_result.hit_cell >= 0) and np.any(numpy_result.hit_cell < 0)


@pytest.mark.parametrize("seed", range(3))
def test_crowds_of_touching_robots_identical(seed):
    rng = np.random.default_rng(10 + seed)
    occ = office(rng)
    rows, cols, ids = crowd(rng, occ, 40)
    visible = rng.random(40) < 0.85
    results = []
    for kernels in ("numpy", "numba"):
        caster = make_caster(occ, RES, ORIGIN, kernels)
        layer = caster.robot_layer()
        layer.update(rows, cols, ids, visible)
        beams = 120
        owner = np.repeat(np.arange(40), beams)
        first = np.searchsorted(ids, np.arange(40))
        centre = np.stack([cols[first] + 5.5, rows[first] + 4.5], axis=1) * RES + np.array(ORIGIN)
        xy = np.repeat(centre, beams, axis=0)
        angles = np.tile(np.linspace(-math.pi, math.pi, beams), 40) + np.repeat(np.arange(40) * 0.1, beams)
        results.append(caster.cast(xy, angles, 5.6, owners=owner, robots=layer))
    assert_identical(results[1], results[0])
    assert np.any(results[0].hit_robot >= 0) and np.any(results[0].hit_robot == SEVERAL_ROBOTS)


def ring_bodies(rng: np.random.Generator, occ: np.ndarray, robots: int):
    """Round robots 40-140 cells across, as Stage rasterises bitmap bodies drawn at a fine resolution: the
    outline and chords across the inside, so a body spans several tiles and its scans leave it through tiles
    holding its own cells only; about a third overlap the robot placed before them (tiles of two robots)."""
    h, w = occ.shape
    rows, cols, ids, centres = [], [], [], []
    for i in range(robots):
        radius = rng.integers(20, 70)
        near = centres and rng.random() < 0.35
        centre = centres[-1] + rng.normal(0, radius, 2) if near else rng.uniform(0, [h, w])
        rr, cc = np.mgrid[int(centre[0]) - radius - 1 : int(centre[0]) + radius + 2,
                          int(centre[1]) - radius - 1 : int(centre[1]) + radius + 2]
        d = np.hypot(rr + 0.5 - centre[0], cc + 0.5 - centre[1])
        body = ((d <= radius) & (d > radius - 1.5)) | ((d < radius) & (rr % 9 == 0))
        rows.append(rr[body])
        cols.append(cc[body])
        ids.append(np.full(int(body.sum()), i))
        centres.append(centre)
    return tuple(np.concatenate(a) for a in (rows, cols, ids)), np.array(centres)


@pytest.mark.parametrize("seed", range(4))
def test_rays_leaving_their_own_robots_body_identical(seed):
    rng = np.random.default_rng(40 + seed)
    occ = office(rng, 330, 400)
    (rows, cols, ids), centres = ring_bodies(rng, occ, 12)
    beams = 180
    xy_own = np.repeat(centres[:, ::-1] * RES + np.array(ORIGIN), beams, axis=0)
    heading = rng.uniform(-math.pi, math.pi, 12)
    heading[::3] = 0.0  # axis-aligned beams among them
    angles_own = (heading[:, None] + np.linspace(-math.pi, math.pi, beams)[None, :]).ravel()
    xy_any, angles_any, reach_any = rays(rng, occ, 20, beams)
    xy = np.concatenate([xy_own, xy_any])
    angles = np.concatenate([angles_own, angles_any])
    reach = np.concatenate([np.full(xy_own.shape[0], 5.6), reach_any])
    owners = np.concatenate([np.repeat(np.arange(12), beams), np.repeat(rng.integers(-1, 12, 20), beams)])
    results = []
    for kernels in ("numpy", "numba"):
        caster = make_caster(occ, RES, ORIGIN, kernels)
        layer = caster.robot_layer()
        layer.update(rows, cols, ids)
        results.append(caster.cast(xy, angles, reach, owners=owners, robots=layer))
    assert_identical(results[1], results[0])
    assert np.any(results[0].hit_robot >= 0) and np.any((results[0].hit_robot == -1) & (results[0].hit_cell >= 0))


@pytest.mark.parametrize("margin", ["wide", "capped", "none"])
def test_rays_beyond_the_stop_maps_margin_identical(margin, monkeypatch):
    """Rays whose reach stays inside the stop map's margin jump through it, the others (origins far off the
    world, or a map capped small, or none) through the region grid: the same answers, cast after cast while
    robots move in the hall's empty regions and with none, and the robots' regions set in the map for a cast
    are reset after it."""
    rng = np.random.default_rng(77)
    occ = np.zeros((300, 400), dtype=bool)  # a walled hall with a few walls in it: mostly empty regions
    occ[[0, -1], :] = occ[:, [0, -1]] = True
    occ[100:102, 40:200] = occ[150:260, 300] = True
    casters = [make_caster(occ, RES, ORIGIN, kernels) for kernels in ("numpy", "numba")]
    regions = casters[1]._grid.slots.size  # the map is made at the first cast
    limit = {"wide": stop_map.STOP_MAP_LIMIT, "capped": regions + 300, "none": regions - 10}[margin]
    monkeypatch.setattr(stop_map, "STOP_MAP_LIMIT", limit)
    layers = [caster.robot_layer() for caster in casters]
    for cast in range(3):
        xy, angles, reach = rays(rng, occ, 40, 90)
        far = rng.random(xy.shape[0] // 90) < 0.3  # scans from up to 40 m off the world, 0.3-30 m long
        xy[np.repeat(far, 90)] += np.repeat(rng.uniform(-40, 40, (int(far.sum()), 2)), 90, axis=0)
        owners = np.repeat(rng.integers(-1, 25, 40), 90)
        rows, cols, ids = crowd(rng, occ, 25)
        results = []
        for caster, layer in zip(casters, layers, strict=True):
            layer.update(rows, cols, ids)
            robots = layer if cast < 2 else None
            results.append(caster.cast(xy, angles, reach, owners=owners, robots=robots))
        assert_identical(results[1], results[0])
        stops = casters[1]._stops  # the robots' regions are no longer set (a stale one would only cost time)
        static = stop_map.StopMap(casters[1]._grid.slots).fitted(30 / RES)[0]
        assert stops.pad < 0 or np.array_equal(stops.cells, static)
    pad = casters[1]._stops.pad
    assert {"wide": pad >= int(1.5 * 30 / RES) // 32, "capped": 0 <= pad < 10, "none": pad == -1}[margin]


def test_step_count_of_a_jump_is_stages():
    """The jumps' integer step count is Stage's ``(int)(n - dist)`` (as far as its sign when not positive),
    also where the jump's fraction lies a hair above a whole number, or the jump is endless or NaN."""
    import numba

    from stage_sim.sensing import region_jumps

    steps_after = numba.njit(lambda steps, jumped: region_jumps.steps_after_jump(steps, jumped))
    rng = np.random.default_rng(5)
    whole = np.concatenate([np.arange(0.0, 70.0), rng.integers(0, 3000, 200).astype(float)])
    tiny = 2.0 ** -np.arange(1, 60)
    jumps = np.concatenate([whole, np.nextafter(whole, np.inf), np.nextafter(whole, -np.inf),
                            (whole[:, None] + tiny[None, :]).ravel(), (whole[:, None] - tiny[None, :]).ravel(),
                            rng.uniform(0, 100, 2000), [1e15, 3e17, 1e300, np.inf, np.nan]])
    jumps = jumps[~(jumps < 0)]
    for steps in (1, 2, 3, 31, 64, 1000, 4095, 5657, 123457, 2**31 - 1):
        for jumped in jumps:
            stage = np.trunc(float(steps) - jumped)
            ours = steps_after(steps, jumped)
            assert (ours > 0) == (stage > 0), (steps, jumped)
            if stage > 0:
                assert ours == stage, (steps, jumped)


def test_threads_do_not_change_answers():
    rng = np.random.default_rng(21)
    occ = office(rng)
    xy, angles, reach = rays(rng, occ, 100, 240)
    rows, cols, ids = crowd(rng, occ, 30)
    owners = np.repeat(rng.integers(-1, 30, 100), 240)
    results = []
    for threads in (1, 2):
        caster = make_caster(occ, RES, ORIGIN, "numba", threads=threads)
        layer = caster.robot_layer()
        layer.update(rows, cols, ids)
        results.append(caster.cast(xy, angles, reach, owners=owners, robots=layer))
    assert_identical(results[1], results[0])


@pytest.mark.parametrize("side", [4, 32])
def test_free_square_fields_are_the_largest_free_squares_within_the_tile(side: int) -> None:
    rng = np.random.default_rng(side)
    occupied = rng.random((40, side, side)) < rng.uniform(0.0, 0.3, (40, 1, 1))
    fields = tile_square_fields(occupied)
    for t, q, y, x in zip(*(rng.integers(0, n, 300) for n in (40, 4, side, side)), strict=True):
        sx, sy = (-1 if q & 1 else 1), (-1 if q & 2 else 1)
        k = 0
        while all(0 <= y + sy * j < side and 0 <= x + sx * i < side and not occupied[t, y + sy * j, x + sx * i]
                  for i in range(k + 1) for j in range(k + 1)):
            k += 1
        assert fields[t, q, y, x] == k
