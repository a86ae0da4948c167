"""Running whole episodes of either environment with a batched policy, and the statistics users compare.

A policy maps (A, D) observations to (A, 2) commands (v, ω) (e.g. :class:`GoalSeeker`); in a discrete
environment each command becomes the nearest action of the table. Statistics per episode are counts, so
that episodes run anywhere (a vector env, Ray tasks) add up to the same totals as a serial run.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass
from typing import Any

import gymnasium
import numpy as np

from stage_sim.envs.baseline import GoalSeeker
from stage_sim.envs.navigate import NavigateEnv
from stage_sim.envs.parallel import NavigateParallelEnv
from stage_sim.envs.task import NavigationTask

Policy = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class EpisodeStats:
    """Outcome of one episode: agents, how many arrived or collided, their summed arrival times (sim s),
    the summed reward of all agents and the steps the episode lasted."""

    agents: int
    arrived: int
    collided: int
    time_to_goal: float
    total_reward: float
    steps: int


def baseline_for(task: NavigationTask) -> GoalSeeker:
    """The goal seeker sized for the first agent's robot (its radius and velocity bounds)."""
    robot = task.sim.robots[task.agents[0]]
    return GoalSeeker(task.layout, float(task.actions.high[0, 0]), float(task.actions.high[0, 1]), robot.radius)


def actions_for(task: NavigationTask, commands: np.ndarray) -> np.ndarray:
    """The environment's actions for wanted commands: the commands themselves, or the nearest table entry."""
    return task.actions.nearest(commands) if task.actions.discrete else commands.astype(np.float32)


def run_single(env: gymnasium.Env, seed: int | None, policy: Policy | None = None) -> EpisodeStats:
    """One episode of a :class:`NavigateEnv` (possibly wrapped)."""
    task = env.unwrapped.task
    policy = policy or baseline_for(task)
    observation, _ = env.reset(seed=seed)
    total, steps = 0.0, 0
    while True:
        action = actions_for(task, policy(observation[None]))[0]
        observation, reward, terminated, truncated, info = env.step(action)
        total += reward
        steps += 1
        if terminated or truncated:
            arrived = int(info["arrived"])
            return EpisodeStats(1, arrived, int(info["collided"]), info["time"] * arrived, total, steps)


def run_parallel(env: NavigateParallelEnv, seed: int | None, policy: Policy | None = None) -> EpisodeStats:
    """One episode of a :class:`NavigateParallelEnv`, all agents driven by one batched policy call per step."""
    policy = policy or baseline_for(env.task)
    observations, _ = env.reset(seed=seed)
    arrived = collided = steps = 0
    time_to_goal = total = 0.0
    while env.agents:
        names = list(observations)
        commands = policy(np.stack([observations[name] for name in names]))
        actions = actions_for(env.task, commands)
        observations, rewards, _, _, infos = env.step(dict(zip(names, actions, strict=True)))
        steps += 1
        total += sum(rewards.values())
        for info in infos.values():
            arrived += info["arrived"]
            collided += info["collided"]
            time_to_goal += info["time"] * info["arrived"]
        observations = {name: observations[name] for name in env.agents}
    return EpisodeStats(len(env.possible_agents), arrived, collided, time_to_goal, total, steps)


def run_vector(envs: gymnasium.vector.VectorEnv, seeds: list[int], policy: Policy) -> list[EpisodeStats]:
    """The first episode of every sub-environment of a vector env of :class:`NavigateEnv` (the batched
    ``NavigateVectorEnv``, or an ``AsyncVectorEnv``, one process per world), sub-environment i seeded with
    ``seeds[i]``; ``policy`` maps the batch of observations to the batch of actions (cast to the action
    space's dtype, as :func:`run_single` does, so that both runs feed the simulation the same numbers)."""
    observations, _ = envs.reset(seed=list(seeds))
    count = len(seeds)
    running = np.ones(count, dtype=bool)
    totals, steps = np.zeros(count), np.zeros(count, dtype=np.int64)
    stats: list[EpisodeStats | None] = [None] * count
    while running.any():
        actions = np.asarray(policy(observations), dtype=envs.single_action_space.dtype)
        observations, rewards, terminated, truncated, infos = envs.step(actions)
        totals += rewards * running
        steps += running
        for i in np.flatnonzero(running & (terminated | truncated)):
            arrived = int(infos["arrived"][i])
            stats[i] = EpisodeStats(1, arrived, int(infos["collided"][i]), float(infos["time"][i]) * arrived,
                                    float(totals[i]), int(steps[i]))
            running[i] = False
    return [s for s in stats if s is not None]


def run_spec(spec: dict[str, Any], seed: int) -> EpisodeStats:
    """One baseline episode of the environment ``spec`` describes: its keyword arguments, plus ``"env"``:
    ``"parallel"`` (the default) or ``"single"``. Plain data in, plain data out: a Ray task or a process
    pool can run it anywhere ``stage_sim[rl]`` is installed."""
    options = dict(spec)
    kind = options.pop("env", "parallel")
    if kind == "single":
        return run_single(NavigateEnv(**options), seed)
    return run_parallel(NavigateParallelEnv(**options), seed)


def summarise(episodes: Iterable[EpisodeStats]) -> dict[str, float]:
    """Success rate, collision rate (per agent) and mean time to goal (sim s, over arrivals)."""
    rows = [asdict(e) for e in episodes]
    agents = sum(r["agents"] for r in rows)
    arrived = sum(r["arrived"] for r in rows)
    return {
        "episodes": len(rows),
        "agents": agents,
        "success_rate": arrived / agents if agents else 0.0,
        "collision_rate": sum(r["collided"] for r in rows) / agents if agents else 0.0,
        "mean_time_to_goal_s": sum(r["time_to_goal"] for r in rows) / arrived if arrived else float("nan"),
    }
