"""Benchmark of the ray casters (numpy reference and numba kernel) against a plain per-ray numba traversal.

Run with the project's venv python: ``.venv/bin/python benchmarks/raycast.py [--poses 100] [--robots 1000]
[--repeats 5]``. Prints one JSON object per line, pinned to one core: ``rays_per_s`` (numpy caster),
``numba_rays_per_s`` (the simulator's compiled kernel, :mod:`stage_sim.sensing.traversal`),
``reference_rays_per_s`` (Stage's walk visiting every cell, the tests' plain port of ``World::Raytrace``) and
their ratios; ``agree``: share of rays whose hit cell equals the reference's; ``numba_identical``: whether the
numba kernel's answers equal the numpy caster's bit for bit.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import numba
import numpy as np

from stage_sim.maps.polygon_raster import outline_points, point_cells
from stage_sim.sensing.casters import make_caster

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.maps.stage_raytrace import raytrace, region_grid  # noqa: E402

RESOLUTION = 0.02  # metres per cell, Stage's default raytrace resolution
MAP_RESOLUTION = 0.05  # metres per pixel of the bitmaps in maps/
POSES = 100
REPEATS = 5
SEED = 7
MAPS = Path(__file__).resolve().parent.parent / "maps"
CASES = ((240, 240.0, 5.6), (1081, 270.0, 30.0))


@numba.njit(cache=True)
def plain_stage_walk(occ, robot, regions, res, xs, ys, angles, rmax, owners, out_range, out_cell):
    """Reference: Stage's walk, one ray at a time, every cell visited (the tests' port of World::Raytrace)."""
    for i in range(xs.shape[0]):
        out_range[i], out_cell[i] = raytrace(occ, 0, 0, regions, 0, 0, xs[i], ys[i], angles[i], rmax, 1.0 / res,
                                             robot, owners[i])


def load_map(name: str) -> tuple[np.ndarray, str]:
    """Bitmap (pixel <= 127 occupied, image row 0 at the top) sampled at 0.02 m cell centres."""
    path = MAPS / f"{name}.png"
    if path.exists():
        from PIL import Image

        img = np.asarray(Image.open(path).convert("L")) <= 127
        label = f"maps/{name}.png"
    else:
        img = procedural_office(1100, 1200)
        label = "procedural office 1200x1100"
    h, w = img.shape
    scale = RESOLUTION / MAP_RESOLUTION
    rows = ((np.arange(round(h / scale)) + 0.5) * scale).astype(np.int64)
    cols = ((np.arange(round(w / scale)) + 0.5) * scale).astype(np.int64)
    return img[::-1][np.ix_(np.minimum(rows, h - 1), np.minimum(cols, w - 1))], label


def procedural_office(h: int, w: int) -> np.ndarray:
    """Stand-in when maps/ lacks a bitmap: 5 m rooms, 2-px walls, doors, desks (pixel grid)."""
    rng = np.random.default_rng(SEED)
    img = np.zeros((h, w), dtype=bool)
    img[:3], img[-3:], img[:, :3], img[:, -3:] = True, True, True, True
    for y in range(0, h, 110):
        img[y : y + 2] = True
    for x in range(0, w, 100):
        img[:, x : x + 2] = True
    for y in range(0, h, 110):
        for x in range(0, w, 100):
            door = x + rng.integers(20, 70)
            img[y : y + 2, door : door + 20] = False
            door = y + rng.integers(20, 80)
            img[door : door + 20, x : x + 2] = False
    for _ in range(300):
        y, x = rng.integers(10, h - 30), rng.integers(10, w - 30)
        img[y : y + rng.integers(5, 20), x : x + rng.integers(5, 25)] = True
    return img


def scan_batch(occ: np.ndarray, poses: int, beams: int, fov_deg: float, rng) -> tuple[np.ndarray, np.ndarray]:
    """``poses`` random free poses, ``beams`` rays each over ``fov_deg``."""
    free = np.argwhere(~occ)
    cells = free[rng.integers(0, len(free), poses)]
    xy = (cells[:, ::-1] + rng.random((poses, 2))) * RESOLUTION
    heading = rng.uniform(-math.pi, math.pi, poses)
    fov = math.radians(fov_deg)
    angles = heading[:, None] + np.linspace(-fov / 2, fov / 2, beams)[None, :]
    return np.repeat(xy, beams, axis=0), angles.ravel()


def best_of(fn, repeats: int) -> float:
    """Shortest wall time of ``repeats`` calls."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def reference(occ, robot, xy, angles, rmax, owners):
    rng_out = np.empty(len(angles))
    cell_out = np.empty(len(angles), dtype=np.int64)
    rows, cols = np.nonzero(occ | (robot != -1))
    regions, low = region_grid(np.stack([cols, rows], axis=1))
    regions = np.pad(regions, ((low[1], 0), (low[0], 0)))  # region (0, 0) at cell (0, 0), as the casters'

    def run():
        plain_stage_walk(occ, robot, regions, RESOLUTION, xy[:, 0], xy[:, 1], angles, rmax, owners, rng_out, cell_out)

    return run, rng_out, cell_out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=POSES, help="scans per map case")
    parser.add_argument("--robots", type=int, default=1000, help="robots of the crowd case")
    parser.add_argument("--repeats", type=int, default=REPEATS, help="timed calls of each caster (the best counts)")
    args = parser.parse_args()
    repeats, single_repeats = args.repeats, 10 * args.repeats
    with contextlib.suppress(AttributeError, OSError):
        os.sched_setaffinity(0, {0})  # one core, as the targets are stated
    rng = np.random.default_rng(SEED)
    no_robot = None
    for name in ("rooms", "office_1200x1100"):
        occ, label = load_map(name)
        caster = make_caster(occ, RESOLUTION, (0.0, 0.0), "numpy")
        fast = make_caster(occ, RESOLUTION, (0.0, 0.0), "numba")
        no_robot = np.full(occ.shape, -1, dtype=np.int32)
        for beams, fov, rmax in CASES:
            xy, angles = scan_batch(occ, args.poses, beams, fov, rng)
            owners = np.full(len(angles), -1, dtype=np.int64)
            run_ref, ref_range, ref_cell = reference(occ, no_robot, xy, angles, rmax, owners)
            run_ref()  # numba warm-up (compilation)
            t_ref = best_of(run_ref, repeats)
            result = caster.cast(xy, angles, rmax)
            t_ours = best_of(lambda c=caster, xy=xy, a=angles, r=rmax: c.cast(xy, a, r), repeats)
            single = best_of(lambda c=caster, xy=xy[:beams], a=angles[:beams], r=rmax: c.cast(xy, a, r),
                             single_repeats)
            fast_result = fast.cast(xy, angles, rmax)
            t_fast = best_of(lambda c=fast, xy=xy, a=angles, r=rmax: c.cast(xy, a, r), repeats)
            fast_single = best_of(lambda c=fast, xy=xy[:beams], a=angles[:beams], r=rmax: c.cast(xy, a, r),
                                  single_repeats)
            emit(
                case=f"{name}_{beams}",
                map=label,
                rays=len(angles),
                beams=beams,
                fov_deg=fov,
                range_m=rmax,
                rays_per_s=len(angles) / t_ours,
                reference_rays_per_s=len(angles) / t_ref,
                ratio_to_reference=t_ref / t_ours,
                agree=float(np.mean(result.hit_cell == ref_cell)),
                max_abs_range_diff_m=float(np.max(np.abs(result.ranges - ref_range))),
                single_scan_ms=single * 1e3,
                numba_rays_per_s=len(angles) / t_fast,
                numba_ratio_to_reference=t_ref / t_fast,
                numba_identical=identical(fast_result, result),
                numba_single_scan_ms=fast_single * 1e3,
            )
    robots_case(occ, label, caster, fast, rng, args.robots, min(repeats, 3))


def identical(a, b) -> bool:
    """Same hit cells, robots and ranges, bit for bit."""
    return bool(np.array_equal(a.hit_cell, b.hit_cell) and np.array_equal(a.hit_robot, b.hit_robot)
                and a.ranges.tobytes() == b.ranges.tobytes())


def robots_case(occ, label, caster, fast, rng, robots, repeats, beams=240, fov=240.0, rmax=5.6):
    """The simulator's big step: every robot's scan, other robots' footprints in the way."""
    xy, angles = scan_batch(occ, robots, beams, fov, rng)
    centres = xy[::beams]
    heading = rng.uniform(-math.pi, math.pi, robots)
    box = np.array([[-0.22, -0.19], [0.22, -0.19], [0.22, 0.19], [-0.22, 0.19]])
    cos, sin = np.cos(heading), np.sin(heading)
    rot = np.stack([np.stack([cos, -sin], -1), np.stack([sin, cos], -1)], -2)
    # Robots as the simulation places them: cells of points sampled along their outlines.
    outline = outline_points(box, RESOLUTION / 2)
    points = centres[:, None, :] + np.einsum("rij,pj->rpi", rot, outline)
    point_ids = np.repeat(np.arange(robots), len(outline))
    owners = np.repeat(np.arange(robots), beams)
    layer = caster.robot_layer()
    fast_layer = fast.robot_layer()

    def footprints():
        flat = point_cells(points, RESOLUTION, (0.0, 0.0), occ.shape).ravel()
        keep = flat >= 0
        return flat[keep] // occ.shape[1], flat[keep] % occ.shape[1], point_ids[keep]

    def step():
        layer.update(*footprints())
        return caster.cast(xy, angles, rmax, owners=owners, robots=layer)

    result = step()
    t_step = best_of(step, repeats)
    t_raster = best_of(footprints, repeats)
    rows, cols, ids = footprints()
    t_update = best_of(lambda: layer.update(rows, cols, ids), repeats)
    t_cast = best_of(lambda: caster.cast(xy, angles, rmax, owners=owners, robots=layer), repeats)
    t_static = best_of(lambda: caster.cast(xy, angles, rmax), repeats)
    fast_layer.update(rows, cols, ids)
    fast_result = fast.cast(xy, angles, rmax, owners=owners, robots=fast_layer)
    t_fast = best_of(lambda: fast.cast(xy, angles, rmax, owners=owners, robots=fast_layer), repeats)
    t_fast_update = best_of(lambda: fast_layer.update(rows, cols, ids), repeats)
    grid = np.full(occ.shape, -1, dtype=np.int32)
    grid[rows, cols] = ids
    shared = grid[rows, cols] != ids  # cells of two or more robots block every ray
    grid[rows[shared], cols[shared]] = -2
    run_ref, _, ref_cell = reference(occ, grid, xy, angles, rmax, owners)
    run_ref()
    t_ref = best_of(run_ref, repeats)
    emit(
        case=f"robots{robots}_{beams}",
        map=label,
        rays=len(angles),
        beams=beams,
        fov_deg=fov,
        range_m=rmax,
        rays_per_s=len(angles) / t_cast,
        reference_rays_per_s=len(angles) / t_ref,
        ratio_to_reference=t_ref / t_cast,
        agree=float(np.mean(result.hit_cell == ref_cell)),
        robot_hits=int(np.count_nonzero(result.hit_robot >= 0)),
        step_ms=t_step * 1e3,
        footprint_cells_ms=t_raster * 1e3,
        layer_update_ms=t_update * 1e3,
        cast_ms=t_cast * 1e3,
        cast_without_robots_ms=t_static * 1e3,
        numba_rays_per_s=len(angles) / t_fast,
        numba_ratio_to_reference=t_ref / t_fast,
        numba_identical=identical(fast_result, result),
        numba_layer_update_ms=t_fast_update * 1e3,
        numba_cast_ms=t_fast * 1e3,
    )


def emit(**fields) -> None:
    """One JSON line, floats rounded for reading."""
    print(json.dumps({k: round(v, 4) if isinstance(v, float) else v for k, v in fields.items()}), flush=True)


if __name__ == "__main__":
    sys.exit(main())
