"""Whole-core speed: simulated seconds per wall second for N robots with B-beam lasers, driving in circles.

Run with the venv's python: ``.venv/bin/python benchmarks/simulate.py [--robots N ...] [--beams B] [--fov DEG]
[--range M] [--kernels numba|numpy] [--threads N]``. Prints one JSON object per line: robots, beams, fov_deg,
range_m, kernels, threads, steps, realtime_factor, ms_per_step, scans_per_s, stalled, peak_rss_mb (of the
process so far: run one configuration per process, robots ascending). With one thread the process is pinned
to one core. Robots are
placed on a 0.6 m lattice of free spots of the rooms map (seeded shuffle) and each drives a 0.6 m-radius
circle (0.3 m/s, 0.5 rad/s); collisions stall them, which the core handles as in any run.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import time
from pathlib import Path

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from stage_sim.maps.raster import build_static_raster  # noqa: E402
from stage_sim.sim.simulation import Simulation  # noqa: E402
from stage_sim.worldfile.loader import load_world_text  # noqa: E402

WORLD = """
resolution 0.02
interval_sim 100
define floorplan model ( color "SlateGray" boundary 1 obstacle_return 1 )
floorplan( size [27.05 21.65 1.0] pose [13.525 10.825 0 0] bitmap "{bitmap}" )
define laser ranger ( sensor( range [0.0 {range}] fov {fov} samples {beams} ) size [0.06 0.06 0.06] )
define bot position ( size [0.4 0.3 0.2] drive "diff" localization "odom" odom_error [0.03 0.03 0 0.05]
                      laser( pose [0.23 0 -0.15 0] ) )
"""
SPACING = 0.6
CLEARANCE = 0.35


def free_spots(count: int, seed: int) -> np.ndarray:
    """``count`` lattice points of the rooms map at least CLEARANCE from any wall (looked up in a small
    window of the raster around each point, so that this set-up does not inflate the measured peak RSS)."""
    text = WORLD.format(bitmap=REPO / "maps/rooms.png", beams=1, fov=240.0, range=5.6)
    raster = build_static_raster(load_world_text(text, str(REPO / "b.world")))
    occupied, res, (ox, oy) = raster.occupied, raster.resolution, raster.origin_xy
    reach = int(np.ceil(CLEARANCE / res)) + 1
    xs, ys = np.meshgrid(np.arange(0.5, 27.0, SPACING), np.arange(0.5, 21.6, SPACING))
    keep = []
    for x, y in zip(xs.ravel(), ys.ravel(), strict=True):
        col, row = int((x - ox) / res), int((y - oy) / res)
        rows, cols = np.nonzero(occupied[max(row - reach, 0) : row + reach, max(col - reach, 0) : col + reach])
        wx = ox + (cols + max(col - reach, 0) + 0.5) * res
        wy = oy + (rows + max(row - reach, 0) + 0.5) * res
        if not np.any((wx - x) ** 2 + (wy - y) ** 2 < CLEARANCE**2):
            keep.append((x, y))
    spots = np.array(keep)
    if len(spots) < count:
        raise SystemExit(f"only {len(spots)} free spots for {count} robots")
    return spots[np.random.default_rng(seed).permutation(len(spots))[:count]]


def world_text(robots: int, beams: int, fov: float, reach: float, seed: int) -> str:
    spots = free_spots(robots, seed)
    yaws = np.random.default_rng(seed + 1).uniform(-180, 180, robots)
    lines = [f"bot( pose [{x:.3f} {y:.3f} 0 {a:.1f}] )" for (x, y), a in zip(spots, yaws, strict=True)]
    return WORLD.format(bitmap=REPO / "maps/rooms.png", beams=beams, fov=fov, range=reach) + "\n".join(lines) + "\n"


def measure(robots: int, args: argparse.Namespace, steps: int) -> dict:
    text = world_text(robots, args.beams, args.fov, args.range, args.seed)
    sim = Simulation(load_world_text(text, str(REPO / "bench.world")), seed=args.seed, kernels=args.kernels,
                     threads=args.threads)
    for i in range(robots):
        sim.set_velocity(i, 0.3, 0.0, 0.5)
    sim.step()  # warm-up (first-use allocations)
    start = time.perf_counter()
    for _ in range(steps):
        sim.step()
    wall = time.perf_counter() - start
    return {
        "robots": robots,
        "beams": args.beams,
        "fov_deg": args.fov,
        "range_m": args.range,
        "kernels": sim.kernels,
        "threads": sim.threads,
        "steps": steps,
        "realtime_factor": round(steps * sim.interval / wall, 2),
        "ms_per_step": round(1000 * wall / steps, 3),
        "scans_per_s": round(robots * steps / wall),
        "stalled": int(sim.stalled.sum()),
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[1, 100, 1000])
    parser.add_argument("--beams", type=int, default=240)
    parser.add_argument("--seconds", type=float, default=None, help="sim seconds per case (default: by size)")
    parser.add_argument("--fov", type=float, default=240.0, help="laser field of view, degrees")
    parser.add_argument("--range", type=float, default=5.6, help="laser range, metres")
    parser.add_argument("--kernels", choices=("numba", "numpy"), default="numba")
    parser.add_argument("--threads", type=int, default=1, help="kernel threads (0: all cores)")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if args.threads == 1 and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})  # one core, as the targets say
    for n in args.robots:
        seconds = args.seconds or (60.0 if n <= 10 else 20.0 if n <= 200 else 5.0)
        print(json.dumps(measure(n, args, max(1, round(seconds / 0.1)))), flush=True)


if __name__ == "__main__":
    main()
