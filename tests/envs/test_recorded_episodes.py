"""Episodes of the obstacles scenario replay bit for bit as they were recorded before resets got cheap.

``tests/data/envs/obstacle_episodes.json`` holds, per case, a SHA-256 of everything an agent and a user see
over a run of seeded episodes (observations, rewards, episode ends, infos, true poses, and a frame of each
episode's world), recorded with the code that parsed a new world text and built a new simulation at every
reset. Any change to how an episode's world is made must leave these digests as they are. To record them
anew (only for a change meant to alter episodes): ``python tests/envs/test_recorded_episodes.py``.
"""

from __future__ import annotations

import hashlib
import json
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from stage_sim.backend import KERNELS_ENV

RECORDED = Path(__file__).resolve().parents[1] / "data" / "envs" / "obstacle_episodes.json"


class Trace:
    """A running SHA-256 over arrays (bytes, dtype and shape) and a count of what went in."""

    def __init__(self) -> None:
        self.hash = hashlib.sha256()
        self.episodes = 0
        self.steps = 0

    def add(self, *values: object) -> None:
        for value in values:
            array = np.ascontiguousarray(value)
            self.hash.update(f"{array.dtype}{array.shape}".encode())
            self.hash.update(array.tobytes())

    def summary(self) -> dict[str, object]:
        return {"episodes": self.episodes, "steps": self.steps, "sha256": self.hash.hexdigest()}


def single(steps: int, frames: bool, **options: object) -> dict[str, object]:
    """``NavigateEnv``: seeded random actions, reset without a seed whenever an episode ends."""
    from stage_sim.envs import NavigateEnv

    env = NavigateEnv(render_mode="rgb_array" if frames else None, **options)
    env.action_space.seed(0)
    trace = Trace()

    def start(seed: int | None) -> None:
        observation, info = env.reset(seed=seed)
        trace.episodes += 1
        trace.add(observation, info["goal"], info["distance"], env.task.sim.true_poses)
        if frames:
            trace.add(env.render())

    start(1)
    for _ in range(steps):
        observation, reward, terminated, truncated, info = env.step(env.action_space.sample())
        trace.steps += 1
        trace.add(observation, reward, terminated, truncated, info["arrived"], info["collided"], info["distance"],
                  info["time"], env.task.sim.true_poses, env.task.sim.odometry_poses)
        if terminated or truncated:
            start(None)
    return trace.summary()


def parallel(steps: int, **options: object) -> dict[str, object]:
    """``NavigateParallelEnv``: every live agent a seeded random action, a new episode when none is left."""
    from stage_sim.envs import NavigateParallelEnv

    env = NavigateParallelEnv(**options)
    for k, agent in enumerate(env.possible_agents):
        env.action_space(agent).seed(k)
    trace = Trace()
    for step in range(steps):
        if not env.agents:
            observations, _ = env.reset(seed=5 if step == 0 else None)
            trace.episodes += 1
            trace.add(*observations.values(), env.task.goals, env.task.sim.true_poses)
        observations, rewards, terminated, truncated, _ = env.step(
            {agent: env.action_space(agent).sample() for agent in env.agents})
        trace.steps += 1
        for agent in sorted(observations):
            trace.add(observations[agent], rewards[agent], terminated[agent], truncated[agent])
        trace.add(env.task.sim.true_poses)
    return trace.summary()


def vector(steps: int, **options: object) -> dict[str, object]:
    """``NavigateVectorEnv``: seeded random actions, Gymnasium's next-step autoreset."""
    from stage_sim.envs import NavigateVectorEnv

    envs = NavigateVectorEnv(**options)
    envs.action_space.seed(3)
    trace = Trace()
    observations, info = envs.reset(seed=11)
    trace.add(observations, info["goal"])
    for _ in range(steps):
        observations, rewards, terminated, truncated, _ = envs.step(envs.action_space.sample())
        trace.steps += 1
        trace.episodes += int(np.count_nonzero(terminated | truncated))
        poses = [envs.simulation(k).true_poses for k in range(envs.num_envs)]
        trace.add(observations, rewards, terminated, truncated, *poses)
    return trace.summary()


SMALL = {"laser_samples": 32}


def _body(**fields: object) -> object:
    from stage_sim.envs import RobotBody

    return RobotBody(**fields)


#: Case name → how to run it. The first is the speed benchmark's scenario (benchmarks/rl_peers.py); the
#: small arena's boxes often reach past its walls, where an episode's world outgrows the base world's grid.
CASES: dict[str, Callable[[], dict[str, object]]] = {
    "benchmark": lambda: single(1200, False, scenario="obstacles", n_obstacles=8, obstacle_size=(0.3, 1.0),
                                arena_size=30.0),
    "small_arena_frames": lambda: single(300, True, scenario="obstacles", n_obstacles=12, arena_size=6.0,
                                         max_steps=25, body=_body(**SMALL)),
    "small_arena_discrete": lambda: single(600, False, scenario="obstacles", n_obstacles=6, arena_size=5.0,
                                           max_steps=15, discrete=True, body=_body(**SMALL)),
    "parallel": lambda: parallel(300, scenario="obstacles", n_robots=3, n_obstacles=10, arena_size=8.0,
                                 max_steps=40, body=_body(**SMALL)),
    "vector": lambda: vector(200, num_envs=3, scenario="obstacles", n_obstacles=10, arena_size=7.0, max_steps=30,
                             body=_body(**SMALL)),
}


@pytest.mark.parametrize("kernels", ["numpy", "numba"])
@pytest.mark.parametrize("case", list(CASES))
def test_episodes_replay_as_recorded(case: str, kernels: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(KERNELS_ENV, kernels)  # the simulation's kernels and the task's step arithmetic
    recorded = json.loads(RECORDED.read_text())[case]
    assert CASES[case]() == recorded


if __name__ == "__main__":
    RECORDED.parent.mkdir(parents=True, exist_ok=True)
    RECORDED.write_text(json.dumps({name: run() for name, run in CASES.items()}, indent=1) + "\n")
    sys.exit(0)
