"""Speed of the RL environments and the baseline's scores, one JSON object per line.

Run pinned to one core: ``taskset -c 0 .venv/bin/python benchmarks/envs.py [--seconds S] [--episodes E]``.

* ``speed``: steps per wall second of ``NavigateEnv`` (one robot) and agent-steps per wall second of
  ``NavigateParallelEnv`` (10 and 100 robots), 512-beam 180° 4 m lasers, a 30 m × 30 m walled arena at
  0.05 m resolution, starts and goals drawn from free space. Every agent drives a fixed arc (0.5 m/s,
  0.3 rad/s); episodes that end (a collision, the 500-step limit) are reset, and resets count in the time.
  ``core_share`` is the part of that time spent inside ``Simulation.step`` (moving robots, casting every
  laser); the rest is the environments' own work (observations, rewards, dicts, resets).
  ``NavigateVectorEnv`` (``--worlds``, default 64 one-robot worlds) counts env steps summed over its worlds.
  For the parallel env, ``robot_steps_per_s`` counts every robot of every step (every laser is cast every
  step, also those of agents that are done and stay as obstacles) and ``agent_steps_per_s`` only the live
  agents.
* ``baseline``: the scripted ``GoalSeeker`` on circle crossing with 4, 10 and 20 robots (the parallel env)
  and on one robot among 8 random boxes (the Gymnasium env): success rate, collision rate and mean time to
  goal in sim seconds, over ``--episodes`` seeds.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from stage_sim.envs import NavigateEnv, NavigateParallelEnv, NavigateVectorEnv
from stage_sim.envs.rollouts import run_parallel, run_single, summarise
from stage_sim.sim.simulation import Simulation

ARENA = {"arena_size": 30.0, "resolution": 0.05}
ARC = np.array([0.5, 0.3], dtype=np.float32)


def single_speed(seconds: float) -> dict:
    """Env steps per wall second of the Gymnasium env, resets included."""
    env = NavigateEnv(scenario="random", **ARENA)
    env.reset(seed=0)
    # The process's first simulation steps on numpy until numba is loaded in the background: time numba only.
    env.task.sim.wait_for_kernels()
    env.step(ARC)
    core = time_core(env.task.sim)
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        _, _, terminated, truncated, _ = env.step(ARC)
        steps += 1
        if terminated or truncated:
            env.reset()
    elapsed = time.perf_counter() - start
    return {"bench": "speed", "env": "NavigateEnv", "robots": 1, "steps": steps,
            "env_steps_per_s": round(steps / elapsed, 1), "core_share": round(core[0] / elapsed, 3)}


def vector_speed(worlds: int, seconds: float) -> dict:
    """Env steps per wall second (summed over worlds) of the vector env, autoresets included."""
    envs = NavigateVectorEnv(worlds, scenario="random", **ARENA)
    envs.reset(seed=0)
    core = [0.0]
    for task in envs.tasks:
        core = time_core(task.sim, core)
    actions = np.repeat(ARC[None], worlds, axis=0)
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        envs.step(actions)
        steps += 1
    elapsed = time.perf_counter() - start
    return {"bench": "speed", "env": "NavigateVectorEnv", "robots": 1, "worlds": worlds, "steps": steps * worlds,
            "env_steps_per_s": round(steps * worlds / elapsed, 1), "core_share": round(core[0] / elapsed, 3)}


def parallel_speed(robots: int, seconds: float) -> dict:
    """Agent-steps per wall second of the PettingZoo env (one env step moves every live agent)."""
    env = NavigateParallelEnv(scenario="random", n_robots=robots, **ARENA)
    env.reset(seed=0)
    core = time_core(env.task.sim)
    steps = agent_steps = 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        if not env.agents:
            env.reset()
        agent_steps += len(env.agents)
        env.step(dict.fromkeys(env.agents, ARC))
        steps += 1
    elapsed = time.perf_counter() - start
    return {"bench": "speed", "env": "NavigateParallelEnv", "robots": robots, "steps": steps,
            "env_steps_per_s": round(steps / elapsed, 1), "robot_steps_per_s": round(steps * robots / elapsed, 1),
            "agent_steps_per_s": round(agent_steps / elapsed, 1),
            "core_share": round(core[0] / elapsed, 3)}


def time_core(sim: Simulation, spent: list[float] | None = None) -> list[float]:
    """Make ``sim`` add the wall seconds of each of its steps to the returned one-element list (``spent``,
    when several simulations share one)."""
    spent = [0.0] if spent is None else spent
    step = sim.step

    def timed_step() -> None:
        start = time.perf_counter()
        step()
        spent[0] += time.perf_counter() - start

    sim.step = timed_step
    return spent


def baseline(episodes: int) -> list[dict]:
    """The goal seeker's scores through both environments."""
    rows = []
    for robots in (4, 10, 20):
        env = NavigateParallelEnv(scenario="circle", n_robots=robots)
        stats = summarise(run_parallel(env, seed) for seed in range(episodes))
        rows.append({"bench": "baseline", "env": "NavigateParallelEnv", "scenario": f"circle_{robots}", **stats})
    env = NavigateEnv(scenario="obstacles", n_obstacles=8)
    stats = summarise(run_single(env, seed) for seed in range(episodes))
    rows.append({"bench": "baseline", "env": "NavigateEnv", "scenario": "obstacles_8", **stats})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="wall seconds per speed measurement")
    parser.add_argument("--episodes", type=int, default=10, help="seeds per baseline scenario (0: speed only)")
    parser.add_argument("--worlds", type=int, nargs="*", default=[64], help="worlds of the vector env runs")
    args = parser.parse_args()
    print(json.dumps(single_speed(args.seconds)), flush=True)
    for worlds in args.worlds:
        print(json.dumps(vector_speed(worlds, args.seconds)), flush=True)
    for robots in (10, 100):
        print(json.dumps(parallel_speed(robots, args.seconds)), flush=True)
    for row in baseline(args.episodes) if args.episodes > 0 else []:
        print(json.dumps({k: round(v, 3) if isinstance(v, float) else v for k, v in row.items()}), flush=True)


if __name__ == "__main__":
    main()
