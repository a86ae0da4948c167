"""Running whole episodes of either environment with a batched policy, and the statistics users compare.

A policy maps (A, D) observations to (A, 2) commands (v, ω) (e.g. :class:`GoalSeeker`); in a discrete
environment each command becomes the nearest action of the table. Statistics per episode are counts, so
that episodes run anywhere (a vector env, Ray tasks) add up to the same totals as a serial run.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass

import gymnasium
import numpy as np

from stage_sim.envs.baseline import GoalSeeker
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
