"""The wanderer on many seeds at once: stall events, longest stop and coverage per seed, then a summary.

``.venv/bin/python benchmarks/wander_sweep.py --seeds N --minutes M [--world W] [--jobs J] [--first-seed S]
[--core]`` runs ``launch_scripts/reactive.py W --duration 60*M --speedup 0 --seed s -g`` (lockstep, no view)
for seeds S..S+N-1, J processes at a time (default: one per core). Each run picks its own private ROS domain
(ROS_DOMAIN_ID is removed from their environment), so runs never hear each other. ``--core`` runs the same
sessions without ROS (:mod:`stage_sim.runs.wander_run`: the same summaries seed for seed, for less CPU).
Prints one JSON line per seed and robot, then one summary line per world; a seed falls short with a stall
event, a stop over 3 s or coverage under 0.95. Exit status 1 when a run fails or a seed falls short.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from concurrent.futures import Executor, ProcessPoolExecutor, ThreadPoolExecutor, as_completed
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
REACTIVE = REPO / "launch_scripts" / "reactive.py"
MAX_STALL_EVENTS, MAX_STOP_S, MIN_COVERAGE = 0, 3.0, 0.95


def run_seed(world: str, seed: int, minutes: float) -> dict:
    """One lockstep session in its own process (and DDS domain); its summaries or its error."""
    env = dict(os.environ)
    env.pop("ROS_DOMAIN_ID", None)
    env.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    start = time.monotonic()
    command = [sys.executable, str(REACTIVE), world, "--duration", f"{minutes * 60:g}", "--speedup", "0",
               "--seed", str(seed), "-g"]
    done = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    result = {"seed": seed, "wall_s": round(time.monotonic() - start, 1), "returncode": done.returncode}
    if done.returncode != 0:
        result["error"] = done.stderr.strip().splitlines()[-1:] or ["no output"]
        return result
    result["robots"] = [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]
    return result


def run_core_seed(world: str, seed: int, minutes: float) -> dict:
    """The same session without ROS, in this process (:mod:`stage_sim.runs.wander_run`)."""
    from stage_sim.runs.wander_run import wander_summaries
    from stage_sim.worldfile.errors import WorldError
    from stage_sim.worldfile.loader import load_world

    start = time.monotonic()
    try:
        description = load_world(world)
    except (WorldError, FileNotFoundError, ValueError) as error:
        return {"seed": seed, "wall_s": 0.0, "returncode": 2, "error": [str(error)]}
    robots = wander_summaries(description, seed, minutes * 60)
    return {"seed": seed, "wall_s": round(time.monotonic() - start, 1), "returncode": 0, "robots": robots}


def falls_short(robot: dict) -> bool:
    return (robot["stall_events"] > MAX_STALL_EVENTS or robot["longest_stop_s"] > MAX_STOP_S
            or robot["coverage"] < MIN_COVERAGE)


def summary(world: str, minutes: float, results: list[dict], path: str) -> dict:
    robots = [r for result in results for r in result.get("robots", [])]
    return {
        "summary": world,
        "path": path,
        "seeds": len(results),
        "sim_minutes": minutes,
        "failed_runs": sorted(r["seed"] for r in results if r["returncode"] != 0),
        "robot_runs": len(robots),
        "stall_events": sum(r["stall_events"] for r in robots),
        "longest_stop_s": max((r["longest_stop_s"] for r in robots), default=None),
        "coverage_min": min((r["coverage"] for r in robots), default=None),
        "coverage_mean": round(sum(r["coverage"] for r in robots) / len(robots), 4) if robots else None,
        "seeds_short": sorted({res["seed"] for res in results for r in res.get("robots", []) if falls_short(r)}),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, required=True, help="how many seeds")
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--minutes", type=float, required=True, help="sim minutes per run")
    parser.add_argument("--world", default="rooms.world", help="a .world file or a bundled world's name")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="runs at a time")
    parser.add_argument("--core", action="store_true", help="run the sessions without ROS (same results)")
    args = parser.parse_args(argv)
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    path = "core" if args.core else "ros"
    results = []
    # ROS: threads that each wait on one session process; core: the sessions in worker processes.
    pool: Executor = ProcessPoolExecutor(args.jobs) if args.core else ThreadPoolExecutor(args.jobs)
    with pool:
        run = run_core_seed if args.core else run_seed
        for future in as_completed([pool.submit(run, args.world, s, args.minutes) for s in seeds]):
            result = future.result()
            results.append(result)
            for robot in result.get("robots", [{"error": result.get("error")}]):
                print(json.dumps({"world": args.world, "path": path, "seed": result["seed"],
                                  "wall_s": result["wall_s"], **robot}), flush=True)
    line = summary(args.world, args.minutes, results, path)
    print(json.dumps(line), flush=True)
    return 1 if line["failed_runs"] or line["seeds_short"] else 0


if __name__ == "__main__":
    sys.exit(main())
