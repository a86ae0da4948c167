"""Large worlds in bounded memory: load time, peak RSS and speed of the two big worlds of issue #14.

Run with the venv's python: ``.venv/bin/python benchmarks/worlds.py [--worlds floorplan rl] [--seconds S]
[--kernels numba|numpy] [--threads N] [--rl-range METRES]``.
Each world runs in its own process (so that each peak RSS is its own) and prints one JSON line: world,
cells (H, W of the world's bounding box), robots, beams, laser_range_m, threads, load_s (world file → ready
``Simulation``, kernels cached; ``import_s`` before it: Python, numpy, numba and stage_sim), steps,
realtime_factor, ms_per_step, peak_rss_mb (the whole process, imports included).

``--rl-range`` shortens (or lengthens) the RL world's lasers, everything else equal: a sweep of it shows where
a step's time goes along a beam (inside the robot's own body, then over the empty regions beyond).

* ``floorplan``: Stage's SFU demo shape: a 1200 m × 600 m floorplan from a 1200 × 615 bitmap at resolution
  0.05 (24000 × 12000 cells), one robot with a 240-beam 240° 5.6 m laser. Stage's own bitmap (from the
  world corpus in ``tests/data/corpus``).
* ``rl``: the multi-robot RL worlds people build on stage_ros2: a 30 m × 30 m map at resolution 0.001
  (30000 × 30000 cells), 200 robots with 0.24 m bitmap bodies and 512-beam 180° 4 m lasers.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

START = time.perf_counter()
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import numpy as np  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

SFU = REPO / "tests" / "data" / "corpus" / "stage-worlds" / "bitmaps" / "SFU_1200x615.png"

FLOORPLAN = """
resolution 0.05
interval_sim 100
define floorplan model ( color "gray30" boundary 1 gui_nose 0 obstacle_return 1 ranger_return 1 )
floorplan( size [1200.000 600.000 0.800] pose [0 -40 0 0] bitmap "{bitmap}" )
define laser ranger ( sensor( range [0.0 5.6] fov 240 samples 240 ) size [0.06 0.06 0.06] )
define bot position ( size [0.4 0.3 0.2] drive "diff" laser( pose [0.13 0 -0.05 0] ) )
bot( pose [{x:.3f} {y:.3f} 0 0] )
"""

RL = """
resolution 0.001
interval_sim 100
define map model ( color "gray30" boundary 1 obstacle_return 1 ranger_return 1 )
map( size [30.000 30.000 0.500] pose [15 15 0 0] bitmap "{bitmap}" )
define laser ranger ( sensor( range [0.0 {laser_range}] fov 180 samples 512 ) size [0.05 0.05 0.05] )
define bot position ( size [0.24 0.24 0.25] drive "diff" bitmap "{robot}" laser( pose [0 0 -0.1 0] ) )
"""
#: The RL world's laser range (m), as issue #14 describes those worlds.
RL_RANGE = 4.0


def office_bitmap(path: Path, width: int, height: int, room: int, seed: int) -> np.ndarray:
    """An office-like floorplan (True = wall): rooms of ``room`` pixels with a door in every wall, a few
    pillars; written as a PNG at ``path``."""
    from PIL import Image

    rng = np.random.default_rng(seed)
    walls = np.zeros((height, width), dtype=bool)
    walls[::room, :] = True
    walls[:, ::room] = True
    walls[[0, -1], :] = walls[:, [0, -1]] = True
    door = max(2, room // 4)
    for r in range(0, height - 1, room):
        for c in range(0, width - 1, room):
            walls[r, c + 1 + rng.integers(room - door - 1):][:door] = False  # a door in the wall below
            walls[r + 1 + rng.integers(room - door - 1):][:door, c] = False  # and in the wall to the left
    pillars = rng.integers(0, [height, width], size=(width * height // (room * room * 4), 2))
    walls[pillars[:, 0], pillars[:, 1]] = True
    walls[[0, -1], :] = walls[:, [0, -1]] = True
    Image.fromarray(np.where(walls, 0, 255).astype(np.uint8), mode="L").save(path)
    return walls


def disc_bitmap(path: Path, pixels: int) -> None:
    """A filled disc: a round robot body."""
    from PIL import Image

    centre = (pixels - 1) / 2
    y, x = np.mgrid[:pixels, :pixels]
    inside = np.hypot(x - centre, y - centre) <= pixels / 2
    Image.fromarray(np.where(inside, 0, 255).astype(np.uint8), mode="L").save(path)


def free_spots(walls: np.ndarray, metres: tuple[float, float], corner: tuple[float, float], clearance: float,
               count: int, seed: int) -> np.ndarray:
    """``count`` points (x, y) of the map at least ``clearance`` from any wall pixel, on a lattice, shuffled."""
    height, width = walls.shape
    px = metres[0] / width
    reach = int(np.ceil(clearance / px)) + 1
    spacing = max(2 * clearance, 0.5)
    xs, ys = np.meshgrid(np.arange(corner[0] + spacing, corner[0] + metres[0] - spacing, spacing),
                         np.arange(corner[1] + spacing, corner[1] + metres[1] - spacing, spacing))
    keep = []
    for x, y in zip(xs.ravel(), ys.ravel(), strict=True):
        col, row = int((x - corner[0]) / px), height - 1 - int((y - corner[1]) / px)
        if not walls[max(row - reach, 0): row + reach, max(col - reach, 0): col + reach].any():
            keep.append((x, y))
    spots = np.array(keep)
    if len(spots) < count:
        raise SystemExit(f"only {len(spots)} free spots for {count} robots")
    return spots[np.random.default_rng(seed).permutation(len(spots))[:count]]


def world_text(name: str, folder: Path, rl_range: float = RL_RANGE) -> str:
    """The world file of case ``name``, its bitmaps written into ``folder`` (``rl_range``: the RL world's
    laser range)."""
    if name == "floorplan":
        from PIL import Image

        bitmap, walls = SFU, np.asarray(Image.open(SFU).convert("L")) <= 127
        # the trimmed bitmap is stretched to 1200 x 600 m centred on (0, -40)
        rows, cols = np.nonzero(walls)
        walls = walls[rows.min(): rows.max() + 1, cols.min(): cols.max() + 1]
        (x, y), = free_spots(walls, (1200.0, 600.0), (-600.0, -340.0), 1.0, 1, seed=1)
        return FLOORPLAN.format(bitmap=bitmap, x=x, y=y)
    walls = office_bitmap(folder / "rl_map.png", 600, 600, 100, seed=2)
    disc_bitmap(folder / "robot.png", 24)
    spots = free_spots(walls, (30.0, 30.0), (0.0, 0.0), 0.3, 200, seed=3)
    yaws = np.random.default_rng(4).uniform(-180, 180, len(spots))
    robots = "".join(f"bot( pose [{x:.3f} {y:.3f} 0 {a:.1f}] )\n" for (x, y), a in zip(spots, yaws, strict=True))
    return RL.format(bitmap=folder / "rl_map.png", robot=folder / "robot.png", laser_range=rl_range) + robots


def measure(name: str, seconds: float, kernels: str, threads: int, rl_range: float) -> dict:
    """Load the world, drive every robot in a circle for ``seconds`` of sim time, report."""
    from stage_sim.sensing.kernels import numba_available
    from stage_sim.sim.simulation import Simulation
    from stage_sim.worldfile.loader import load_world_text

    numba_available()  # the import of numba counts as an import, not as loading the world
    imported = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        text = world_text(name, Path(folder), rl_range)
        begin = time.perf_counter()
        sim = Simulation(load_world_text(text, str(Path(folder) / f"{name}.world")), seed=1, kernels=kernels,
                         threads=threads)
        load = time.perf_counter() - begin
    for i in range(len(sim.robots)):
        sim.set_velocity(i, 0.3, 0.0, 0.5)
    sim.step()  # first-use allocations
    steps = max(1, round(seconds / sim.interval))
    begin = time.perf_counter()
    for _ in range(steps):
        sim.step()
    wall = time.perf_counter() - begin
    return {
        "world": name,
        "cells": list(sim.static.shape),
        "resolution": sim.static.resolution,
        "robots": len(sim.robots),
        "beams": int(sum(r.sensor.samples for robot in sim.robots for r in robot.rangers)),
        "laser_range_m": max(r.sensor.range_max for robot in sim.robots for r in robot.rangers),
        "threads": threads,
        "import_s": round(imported - START, 2),
        "load_s": round(load, 2),
        "steps": steps,
        "realtime_factor": round(steps * sim.interval / wall, 2),
        "ms_per_step": round(1000 * wall / steps, 2),
        "kernels": sim.kernels,
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", nargs="+", choices=("floorplan", "rl"), default=["floorplan", "rl"])
    parser.add_argument("--seconds", type=float, default=10.0, help="sim seconds per world")
    parser.add_argument("--kernels", choices=("numba", "numpy"), default="numba")
    parser.add_argument("--threads", type=int, default=1, help="numba threads (the table's rows: 1)")
    parser.add_argument("--rl-range", type=float, default=RL_RANGE, help="the RL world's laser range (m)")
    parser.add_argument("--child", choices=("floorplan", "rl"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(measure(args.child, args.seconds, args.kernels, args.threads, args.rl_range)), flush=True)
        return
    for name in args.worlds:
        subprocess.run([sys.executable, __file__, "--child", name, "--seconds", str(args.seconds), "--kernels",
                        args.kernels, "--threads", str(args.threads), "--rl-range", str(args.rl_range)], check=True)


if __name__ == "__main__":
    main()
