"""The wanderer's cost per decision, apart from the simulation's: the core WanderDriver on a world, closed loop.

``.venv/bin/python benchmarks/wander_speed.py [--world W ...] [--steps N] [--seed S] [--profile]`` steps each
world N times (default rooms.world, 1800 steps = 3 sim-minutes) with the wanderer deciding before every step,
and prints one JSON line per world: decisions, wander_ms per decision and step_ms per simulation step (CPU
time of this process, less disturbed by other load than wall time), wall_s. The runs are deterministic for a
seed, so two trees that decide identically time the same decisions.
``--profile`` prints the wanderer's ten costliest functions (cProfile, cumulative) to stderr. Pin with
``taskset -c 0`` and run on a quiet machine: figures taken under load are noisy.
"""

from __future__ import annotations

import argparse
import cProfile
import json
import pstats
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from stage_sim.runs.driver import WanderDriver  # noqa: E402
from stage_sim.sim.simulation import Simulation  # noqa: E402
from stage_sim.worldfile.loader import load_world  # noqa: E402


def measure(world: str, steps: int, seed: int, profiler: cProfile.Profile | None) -> dict:
    """Time ``steps`` decisions and simulation steps of one seeded run."""
    sim = Simulation(load_world(world), seed=seed)
    driver = WanderDriver(sim, seed)
    wander_s = step_s = 0.0
    start = time.perf_counter()
    for _ in range(steps):
        t0 = time.process_time()
        if profiler:
            profiler.enable()
        driver.decide()
        if profiler:
            profiler.disable()
        t1 = time.process_time()
        sim.step()
        wander_s, step_s = wander_s + t1 - t0, step_s + time.process_time() - t1
    decisions = steps * len(driver.wanderers)
    return {"world": world, "seed": seed, "steps": steps, "decisions": decisions,
            "wander_ms": round(1000 * wander_s / decisions, 3), "step_ms": round(1000 * step_s / steps, 3),
            "wall_s": round(time.perf_counter() - start, 2)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", nargs="+", default=["rooms.world"], help="worlds (files or bundled names)")
    parser.add_argument("--steps", type=int, default=1800)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--profile", action="store_true", help="cProfile the wanderer (slows it down)")
    args = parser.parse_args(argv)
    profiler = cProfile.Profile() if args.profile else None
    for world in args.world:
        print(json.dumps(measure(world, args.steps, args.seed, profiler)), flush=True)
    if profiler:
        pstats.Stats(profiler, stream=sys.stderr).sort_stats("tottime").print_stats(12)
    return 0


if __name__ == "__main__":
    sys.exit(main())
