"""Independent one-robot worlds as one PettingZoo env: API and seed tests, and the same episodes as NavigateEnv."""

from __future__ import annotations

import numpy as np
from pettingzoo.test import parallel_api_test, parallel_seed_test

from stage_sim.envs import NavigateEnv, NavigateParallelVectorEnv, RobotBody

SMALL = RobotBody(laser_samples=32)
KWARGS = {"body": SMALL, "scenario": "obstacles", "n_obstacles": 4, "max_steps": 12}


def test_pettingzoo_api_and_seed_tests_pass():
    parallel_api_test(NavigateParallelVectorEnv(3, **KWARGS), num_cycles=40)
    parallel_seed_test(lambda: NavigateParallelVectorEnv(3, **KWARGS))


def test_agent_i_lives_the_episode_of_a_navigate_env_seeded_with_seed_plus_i_and_leaves_when_it_ends():
    env = NavigateParallelVectorEnv(3, **KWARGS)
    singles = [NavigateEnv(**KWARGS) for _ in range(3)]
    observations, _ = env.reset(seed=20)
    for i, single in enumerate(singles):
        assert np.array_equal(observations[f"world_{i}"], single.reset(seed=20 + i)[0])
    rng = np.random.default_rng(0)
    space = env.action_space("world_0")
    running = set(env.agents)
    while env.agents:
        actions = {name: rng.uniform(space.low, space.high).astype(np.float32) for name in env.agents}
        observations, rewards, terminated, truncated, _ = env.step(actions)
        for name, action in actions.items():
            observation, reward, single_terminated, single_truncated, _ = singles[int(name[6:])].step(action)
            assert np.array_equal(observations[name], observation) and rewards[name] == reward
            assert (terminated[name], truncated[name]) == (single_terminated, single_truncated)
            if single_terminated or single_truncated:
                running.discard(name)
        assert set(env.agents) == running
