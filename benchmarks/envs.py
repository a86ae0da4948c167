"""Speed of the RL environments and the baseline's scores, one JSON object per line.

Run pinned to one core: ``taskset -c 0 .venv/bin/python benchmarks/envs.py [--seconds S] [--episodes E]``.

* ``speed``: steps per wall second of ``NavigateEnv`` (one robot) and agent-steps per wall second of
  ``NavigateParallelEnv`` (10 and 100 robots), 512-beam 180° 4 m lasers, a 30 m × 30 m walled arena at
  0.05 m resolution, starts and goals drawn from free space. Every agent drives a fixed arc (0.5 m/s,
  0.3 rad/s); episodes that end (a collision, the 500-step limit) are reset, and resets count in the time.
  ``core_share`` is the part of that time spent inside ``Simulation.step`` (moving robots, casting every
  laser; ``Simulation.step_with`` when an env's step is one compiled call, which then makes the commands,
  observations and rewards too; for the vector env its ``SimulationBatch.step``); the rest is the environments'
  own work (dicts, resets; observations and rewards where they are not in that call).
  ``NavigateVectorEnv`` (``--worlds``, default 64 one-robot worlds) counts env steps summed over its worlds.
  For the parallel env, ``robot_steps_per_s`` counts every robot of every step (every laser is cast every
  step, also those of agents that are done and stay as obstacles) and ``agent_steps_per_s`` only the live
  agents.
* ``breakdown``: where the time of a one-robot ``NavigateEnv`` step goes on ``benchmarks/rl_peers.py``'s
  scenario (the obstacles scenario: 8 boxes of 0.3–1 m drawn anew each episode, a uniformly random action per
  step, episodes reset as they end): ``kernel_us`` inside the compiled call (moves, contacts and the ray walk;
  with the task's commands, observation and reward, which the env's step makes in the same call),
  ``step_glue_us`` the rest of ``Simulation.step_with`` (Python and numpy around it), ``env_us`` the env's own
  Python per step (actions, result, info), ``reset_us`` the resets' time per step
  (``ms_per_reset`` each: a new world with the episode's boxes, free space, placement). The same for the vector
  env of ``--worlds`` worlds, per world step: its worlds step in one compiled call
  (:class:`~stage_sim.sim.simulation.SimulationBatch`), whose time per world is ``kernel_us``, and
  ``step_glue_us`` is the batch's Python per world. The envs are timed in turns, ``--seconds`` each in
  :data:`SLICES` slices, so that a slow phase of the machine weighs on both rows alike.
* ``memory``: what one world more holds in a vector env (the obstacles scenario and the fixed ``random`` one;
  the full robot body, 512 beams): Python's traced bytes after a reset and 5 steps of 9 worlds, less those of 3
  worlds, over 6, on the compiled kernels (the base world's own share is held once, outside the difference).
* ``baseline``: the scripted ``GoalSeeker`` on circle crossing with 4, 10 and 20 robots (the parallel env)
  and on one robot among 8 random boxes (the Gymnasium env): success rate, collision rate and mean time to
  goal in sim seconds, over ``--episodes`` seeds.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import sys
import time
import tracemalloc
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from stage_sim.backend import KERNELS_ENV
from stage_sim.envs import NavigateEnv, NavigateParallelEnv, NavigateVectorEnv
from stage_sim.envs.rollouts import run_parallel, run_single, summarise
from stage_sim.sim.simulation import Simulation, SimulationBatch

ARENA = {"arena_size": 30.0, "resolution": 0.05}
ARC = np.array([0.5, 0.3], dtype=np.float32)


def single_speed(seconds: float) -> dict:
    """Env steps per wall second of the Gymnasium env, resets included."""
    env = NavigateEnv(scenario="random", **ARENA)
    env.reset(seed=0)
    # The process's first simulation steps on numpy until numba is loaded in the background: time numba only. The
    # first step adopts numba, the second loads the env's own compiled kernels (compiling them on a cold cache).
    env.task.sim.wait_for_kernels()
    env.step(ARC)
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
    batch_step = SimulationBatch.step  # the worlds step together, in one call of the batch

    def timed_step(batch: SimulationBatch, *args: object) -> None:
        start = time.perf_counter()
        batch_step(batch, *args)
        core[0] += time.perf_counter() - start

    actions = np.repeat(ARC[None], worlds, axis=0)
    SimulationBatch.step = timed_step
    try:
        steps, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds:
            envs.step(actions)
            steps += 1
        elapsed = time.perf_counter() - start
    finally:
        SimulationBatch.step = batch_step
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


#: Slices the breakdowns' seconds are cut into, the envs taking turns (VM phases then hit them alike).
SLICES = 6


class Breakdown:
    """Where an env step's time goes (see the module's docstring), on the compiled kernels: ``NavigateEnv``, or
    with ``worlds`` the vector env of that many one-robot worlds (then per world step, its autoresets timed
    where they happen, inside its ``step``). :meth:`measure` adds to what earlier slices measured."""

    def __init__(self, worlds: int = 0) -> None:
        scenario = {"scenario": "obstacles", "n_obstacles": 8, "obstacle_size": (0.3, 1.0), **ARENA}
        self.worlds = worlds
        self.env = NavigateVectorEnv(worlds, **scenario) if worlds else NavigateEnv(**scenario)
        self.env.reset(seed=0)
        for sim in [self.env.simulation(k) for k in range(worlds)] if worlds else [self.env.task.sim]:
            sim.wait_for_kernels()
        rng = np.random.default_rng(1)
        self.count = count = max(worlds, 1)
        self.actions = np.stack([rng.uniform(0.0, 1.0, (1000, count)),
                                 rng.uniform(-np.pi / 2, np.pi / 2, (1000, count))], -1).astype(np.float32)
        self.env.step(self.actions[0] if worlds else self.actions[0, 0])  # its kernels loaded before the clock
        self.spent = {"kernel": 0.0, "step": 0.0, "reset": 0.0}
        self.resets = self.steps = 0
        self.elapsed = 0.0

    def measure(self, seconds: float) -> None:
        """Step for ``seconds`` more, the compiled step, the rest of the simulation's step and the resets timed."""
        from stage_sim.envs.task import NavigationTask
        from stage_sim.sim import fused_kernels

        spent, worlds, count, actions, env = self.spent, self.worlds, self.count, self.actions, self.env
        # the compiled step: one world's (with the task's commands and observations when the env steps in one
        # call), or every world's in one call (the vector env's SimulationBatch; its kernel calls the other,
        # which must stay the compiled one)
        kernels = {name: getattr(fused_kernels, name) for name in (("whole_steps",) if worlds else ("commanded_step",))}
        stepper = SimulationBatch if worlds else Simulation
        step, step_with, reset = stepper.step, Simulation.step_with, NavigationTask.reset

        def timed(kernel: Callable[..., object]) -> Callable[..., object]:
            def timed_kernel(*args: object) -> object:
                start = time.perf_counter()
                try:
                    return kernel(*args)
                finally:
                    spent["kernel"] += time.perf_counter() - start
            return timed_kernel

        def timed_step(*args: object) -> None:
            start = time.perf_counter()
            step(*args)
            spent["step"] += time.perf_counter() - start

        def timed_step_with(sim: Simulation, kernel: Callable[..., int], arguments: tuple) -> bool:
            start = time.perf_counter()
            try:
                return step_with(sim, timed(kernel), arguments)
            finally:
                spent["step"] += time.perf_counter() - start

        def timed_reset(task: NavigationTask, generator: np.random.Generator) -> np.ndarray:
            inside = spent["kernel"], spent["step"]
            began = time.perf_counter()
            observations = reset(task, generator)
            spent["reset"] += time.perf_counter() - began
            spent["kernel"], spent["step"] = inside  # a reset's own still step counts in the reset
            self.resets += 1
            return observations

        for name, kernel in kernels.items():
            setattr(fused_kernels, name, timed(kernel))
        stepper.step, NavigationTask.reset = timed_step, timed_reset
        if not worlds:
            Simulation.step_with = timed_step_with
        try:
            steps = self.steps
            start = time.perf_counter()
            while time.perf_counter() - start < seconds:
                if worlds:
                    env.step(actions[steps // count % len(actions)])
                else:
                    _, _, terminated, truncated, _ = env.step(actions[steps % len(actions), 0])
                    if terminated or truncated:
                        env.reset()
                steps += count
            self.elapsed += time.perf_counter() - start
            self.steps = steps
        finally:
            for name, kernel in kernels.items():
                setattr(fused_kernels, name, kernel)
            stepper.step, Simulation.step_with, NavigationTask.reset = step, step_with, reset

    def row(self) -> dict:
        """The JSON line of what was measured."""
        steps, spent = self.steps, self.spent
        per_step = {key: value / steps * 1e6 for key, value in spent.items()}
        return {"bench": "breakdown", "env": type(self.env).__name__, "worlds": self.count,
                "scenario": "obstacles_8", "steps": steps, "resets": self.resets,
                "env_steps_per_s": round(steps / self.elapsed, 1), "us_per_step": round(self.elapsed / steps * 1e6, 1),
                "kernel_us": round(per_step["kernel"], 1),
                "step_glue_us": round(per_step["step"] - per_step["kernel"], 1),
                "env_us": round(self.elapsed / steps * 1e6 - per_step["step"] - per_step["reset"], 1),
                "reset_us": round(per_step["reset"], 1),
                "ms_per_reset": round(spent["reset"] / max(self.resets, 1) * 1e3, 2)}


def breakdowns(seconds: float, worlds: list[int]) -> list[dict]:
    """:class:`Breakdown` of ``NavigateEnv`` and of the vector env of each of ``worlds``, ``seconds`` each, in
    :data:`SLICES` slices taken in turn."""
    runs = [Breakdown(), *(Breakdown(count) for count in worlds)]
    for _ in range(SLICES):
        for run in runs:
            run.measure(seconds / SLICES)
    return [run.row() for run in runs]


def time_core(sim: Simulation) -> list[float]:
    """Make ``sim`` add the wall seconds of each of its steps (those an env makes in one call too) to the returned
    one-element list."""
    spent = [0.0]
    step, step_with = sim.step, sim.step_with

    def timed_step() -> None:
        start = time.perf_counter()
        step()
        spent[0] += time.perf_counter() - start

    def timed_step_with(kernel: Callable[..., int], arguments: tuple) -> bool:
        start = time.perf_counter()
        try:
            return step_with(kernel, arguments)
        finally:
            spent[0] += time.perf_counter() - start

    sim.step, sim.step_with = timed_step, timed_step_with
    return spent


def world_memory(scenario: str) -> dict:
    """Traced bytes one world more adds to a vector env of the ``scenario`` (see the module's docstring)."""
    def held(count: int) -> int:
        gc.collect()
        tracemalloc.start()
        try:
            envs = NavigateVectorEnv(count, scenario=scenario, n_obstacles=8, **ARENA)
            envs.reset(seed=0)
            for _ in range(5):
                envs.step(np.repeat(ARC[None], count, axis=0))
            gc.collect()
            return tracemalloc.get_traced_memory()[0]
        finally:
            tracemalloc.stop()

    asked = os.environ.get(KERNELS_ENV)
    os.environ[KERNELS_ENV] = "numba"  # from the first step: numpy's tables are others
    try:
        held(1)  # the kernels loaded, outside the count
        few, many = 3, 9
        per_world = (held(many) - held(few)) / (many - few)
    finally:
        if asked is None:
            del os.environ[KERNELS_ENV]
        else:
            os.environ[KERNELS_ENV] = asked
    return {"bench": "memory", "env": "NavigateVectorEnv", "scenario": scenario, "worlds": [few, many],
            "kb_per_world": round(per_world / 1e3, 1)}


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
    for row in breakdowns(args.seconds, args.worlds):
        print(json.dumps(row), flush=True)
    for robots in (10, 100):
        print(json.dumps(parallel_speed(robots, args.seconds)), flush=True)
    for scenario in ("obstacles", "random"):
        print(json.dumps(world_memory(scenario)), flush=True)
    for row in baseline(args.episodes) if args.episodes > 0 else []:
        print(json.dumps({k: round(v, 3) if isinstance(v, float) else v for k, v in row.items()}), flush=True)


if __name__ == "__main__":
    main()
