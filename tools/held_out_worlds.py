"""Held-out multi-robot worlds for the robot fidelity tests: a recorded world with new headings (and, with
``--robots``, a new random subset of its start positions), drawn from a seed.

  .venv/bin/python tools/held_out_worlds.py tests/data/fidelity/robots/crowd_1000.world 11 --robots 100 \
      > tests/data/fidelity/robots/crowd_100_seed11.world

The Stage answers for such a world are recorded with ``../shared/tools/stage/golden.py`` (on a copy whose
first line is ``quit_time 3600`` and whose robot define carries ``ctrl "perf"``).
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import numpy as np

ROBOT = re.compile(r'^bot\( pose \[(\S+) (\S+) (\S+) (\S+)\] \)$')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("world", type=Path)
    parser.add_argument("seed", type=int)
    parser.add_argument("--robots", type=int, default=None, help="how many start positions to keep (default all)")
    args = parser.parse_args()
    lines = args.world.read_text().splitlines()
    head = [line for line in lines if not ROBOT.match(line)]
    starts = [ROBOT.match(line).groups()[:3] for line in lines if ROBOT.match(line)]
    rng = np.random.default_rng(args.seed)
    chosen = rng.permutation(len(starts))[: args.robots or len(starts)]
    headings = rng.uniform(-180.0, 180.0, chosen.size)
    body = [f"bot( pose [{starts[i][0]} {starts[i][1]} {starts[i][2]} {a:.1f}] )"
            for i, a in zip(chosen, headings, strict=True)]
    sys.stdout.write("\n".join(head + body) + "\n")


if __name__ == "__main__":
    main()
