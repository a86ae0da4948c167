"""How close stage_sim's scans are to the real Stage 4.3: the golden scans in ``tests/data/fidelity``.

Run with the venv's python: ``.venv/bin/python benchmarks/fidelity.py [--variants A B C]`` (the recordings
are part of the repository). For every variant (A: rooms.world,
B: resolution 0.05, C: floorplan turned by 30°) it prints one JSON object per line and source:

* ``stage_sim``: stage_sim's first scan at each recorded pose;
* ``stage-walk-on-stage_sim-raster``: Stage's own ray walk (tests/maps/stage_raytrace.py) replayed on
  stage_sim's static raster, which shows how much of the difference the raster accounts for;

then the same figures as a table. Figures: share of beams within 1 and 1.5 cells of Stage's range, share
identical to 1 mm, share of hit/miss disagreements, mean Stage − ours on beams both hit (cells, cm).

Then robots among robots (``tests/data/fidelity/robots``, issue #32): per world one JSON object with
``"robots_world"``: the share of beams identical to 1 mm (and within 1.5 cells) of Stage's first scans with
every robot standing, the share of robots within 1 mm of Stage's pose after driving circles for the
recorded time, and the number of stall flags differing then; and the same as a table.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.maps.golden import VARIANTS, figures, load_golden, stage_reference_scans, stage_sim_scans  # noqa: E402
from tests.sim.robot_golden import WORLDS, robot_figures  # noqa: E402

RANGE_MAX = 5.6
ROBOT_GOALS = ("goals (issue #32): scans identical >= 99.9 %, on Stage's path >= 95 % (crowd_1000: 80 %), "
               "stall flags differing <= 1 % of robots")
GOALS = "goals: within 1 cell >= 95 %, within 1.5 cells >= 99 %, |mean| <= 0.2 cell, hit/miss <= 0.05 %"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=VARIANTS)
    parser.add_argument("--robot-worlds", nargs="*", default=list(WORLDS), choices=WORLDS)
    parser.add_argument("--robot-seconds", type=float, default=None,
                        help="sim seconds to drive the robots (default: each world's recorded time)")
    args = parser.parse_args()
    rows = []
    for variant in args.variants:
        golden = load_golden(variant)
        stage = np.array([scan.ranges for scan in golden])
        resolution = 0.05 if variant == "B" else 0.02
        sources = (("stage_sim", stage_sim_scans), ("stage-walk-on-stage_sim-raster", stage_reference_scans))
        for source, scans in sources:
            start = time.perf_counter()
            result = figures(variant, source, stage, scans(golden), resolution, RANGE_MAX)
            line = result.as_dict() | {"seconds": round(time.perf_counter() - start, 2)}
            print(json.dumps(line), flush=True)
            rows.append(result)
    print()
    print("| variant | source | within 1 cell | within 1.5 cells | identical (< 1 mm) | hit/miss "
          "| Stage − ours, mean |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r.variant} | {r.source} | {r.within_1_cell:.2%} | {r.within_1_5_cells:.2%} | {r.identical:.2%} "
              f"| {r.hit_miss:.2%} | {r.mean_diff_cells:+.2f} cell ({r.mean_diff_cm:+.2f} cm) |")
    print(GOALS)
    robots = []
    for world in args.robot_worlds:
        start = time.perf_counter()
        result = robot_figures(world, args.robot_seconds)
        robots.append(result)
        line = {"robots_world": world} | result.as_dict() | {"wall_seconds": round(time.perf_counter() - start, 2)}
        del line["world"]
        print(json.dumps(line), flush=True)
    if robots:
        print()
        print("| world | robots | scans identical (< 1 mm) | within 1.5 cells | on Stage's path at the end "
              "| stall flags differing | seconds driven |")
        print("|---|---|---|---|---|---|---|")
        for r in robots:
            print(f"| {r.world} | {r.robots} | {r.scans_identical:.3%} | {r.scans_within_1_5_cells:.3%} "
                  f"| {r.on_path:.1%} | {r.stalls_differing} | {r.seconds:g} |")
        print(ROBOT_GOALS)


if __name__ == "__main__":
    main()
