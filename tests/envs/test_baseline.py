"""The scripted baseline reaches its goals through both environments, and its statistics add up."""

from __future__ import annotations

import math

import pytest

from stage_sim.envs import NavigateEnv, NavigateParallelEnv, RobotBody
from stage_sim.envs.rollouts import EpisodeStats, run_parallel, run_single, summarise

SMALL = RobotBody(laser_samples=64)


def test_the_goal_seeker_reaches_goals_among_random_boxes():
    env = NavigateEnv(scenario="obstacles", n_obstacles=6, body=SMALL)
    episodes = [run_single(env, seed) for seed in range(3)]
    assert [e.arrived for e in episodes] == [1, 1, 1]
    assert all(e.total_reward > 0 for e in episodes)


def test_the_goal_seeker_crosses_a_circle_of_four_robots_without_collision():
    env = NavigateParallelEnv(scenario="circle", n_robots=4, body=SMALL)
    episode = run_parallel(env, seed=0)
    assert (episode.agents, episode.arrived, episode.collided) == (4, 4, 0)
    # The circle's diameter is 8 m and the robots drive at most 1 m/s.
    assert episode.time_to_goal / 4 >= 8.0 - 2 * 0.3


def test_the_goal_seeker_drives_the_discrete_variant_through_the_nearest_table_entries():
    episode = run_single(NavigateEnv(body=SMALL, discrete=True), seed=1)
    assert episode.arrived == 1


def test_summary_rates_are_per_agent_and_the_time_is_per_arrival():
    summary = summarise([EpisodeStats(4, 3, 1, 30.0, 0.0, 100), EpisodeStats(2, 1, 0, 6.0, 0.0, 500)])
    assert summary == {"episodes": 2, "agents": 6, "success_rate": 4 / 6, "collision_rate": 1 / 6,
                       "mean_time_to_goal_s": 9.0}
    assert math.isnan(summarise([EpisodeStats(1, 0, 1, 0.0, -10.0, 3)])["mean_time_to_goal_s"])
    assert summarise([])["agents"] == 0


@pytest.mark.parametrize("robots", [1, 3])
def test_episode_counts_never_exceed_the_agents(robots):
    env = NavigateParallelEnv(scenario="random", n_robots=robots, body=SMALL, max_steps=20)
    episode = run_parallel(env, seed=4)
    assert episode.arrived + episode.collided <= robots
    assert episode.steps <= 20
