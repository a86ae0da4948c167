"""How close stage_sim's scans are to the real Stage 4.3: the golden scans in ``tests/data/fidelity``.

Run with the venv's python: ``.venv/bin/python benchmarks/fidelity.py [--variants A B C]`` (the recordings
are part of the repository). For every variant (A: rooms.world,
B: resolution 0.05, C: floorplan turned by 30°) it prints one JSON object per line and source:

* ``stage_sim``: stage_sim's first scan at each recorded pose;
* ``stage-walk-on-stage_sim-raster``: Stage's own ray walk (tests/maps/stage_raytrace.py) replayed on
  stage_sim's static raster, which shows how much of the difference the raster accounts for;

then the same figures as a table. Figures: share of beams within 1 and 1.5 cells of Stage's range, share
identical to 1 mm, share of hit/miss disagreements, mean Stage − ours on beams both hit (cells, cm).
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

RANGE_MAX = 5.6
GOALS = "goals: within 1 cell >= 95 %, within 1.5 cells >= 99 %, |mean| <= 0.2 cell, hit/miss <= 0.05 %"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=VARIANTS)
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


if __name__ == "__main__":
    main()
