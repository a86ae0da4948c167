"""The many-robot PettingZoo environment: API and seed tests, scenarios, agents leaving, one step for all."""

from __future__ import annotations

import numpy as np
import pytest
from pettingzoo.test import parallel_api_test, parallel_seed_test

from stage_sim.envs import NavigateParallelEnv, RewardConfig, RobotBody

SMALL = RobotBody(laser_samples=32)


def test_pettingzoo_api_and_seed_tests_pass():
    parallel_api_test(NavigateParallelEnv(n_robots=3, body=SMALL, max_steps=40), num_cycles=60)
    parallel_seed_test(lambda: NavigateParallelEnv(scenario="obstacles", n_robots=3, body=SMALL, max_steps=40))


def test_circle_crossing_puts_robots_on_a_circle_with_antipodal_goals():
    env = NavigateParallelEnv(n_robots=6, body=SMALL, circle_radius=3.0, circle_jitter=0.0)
    observations, infos = env.reset(seed=5)
    assert env.agents == [f"robot_{i}" for i in range(6)]
    poses = env.task.sim.true_poses
    assert np.hypot(poses[:, 0], poses[:, 1]) == pytest.approx(np.full(6, 3.0))
    goals = np.array([infos[name]["goal"] for name in env.agents])
    assert goals == pytest.approx(-poses[:, :2])
    assert [observations[name][-3] for name in env.agents] == pytest.approx(np.zeros(6), abs=1e-6)  # facing goals
    assert [observations[name][-4] for name in env.agents] == pytest.approx(np.full(6, 6.0), abs=1e-5)


def test_all_robots_move_in_one_simulation_step():
    env = NavigateParallelEnv(n_robots=5, body=SMALL)
    env.reset(seed=1)
    before_time, before = env.task.sim.sim_time, env.task.sim.true_poses.copy()
    env.step({name: np.array([0.5, 0.0], dtype=np.float32) for name in env.agents})
    assert env.task.sim.sim_time == pytest.approx(before_time + env.task.sim.interval)
    moved = np.hypot(*(env.task.sim.true_poses[:, :2] - before[:, :2]).T)
    assert moved == pytest.approx(np.full(5, 0.05))


def test_an_agent_that_arrives_or_collides_leaves_and_its_robot_stays_put():
    reward = RewardConfig(progress=0.0, arrival=10.0, collision=10.0, time=0.01, goal_tolerance=1.0)
    env = NavigateParallelEnv(n_robots=2, body=SMALL, reward=reward)
    env.reset(seed=3)
    env.task.goals[0] = env.task.sim.true_poses[0, :2] + 0.5  # robot_0 is already within 1 m of its goal
    inner_face = env.task.scenario.source.arena_size / 2 - 0.05
    env.task.sim.set_pose(1, inner_face - 0.25, 0.0, 0.0)  # robot_1 faces the east wall, 0.05 m off
    _, rewards, terminated, _, infos = env.step({name: np.array([1.0, 0.0], dtype=np.float32) for name in env.agents})
    assert terminated == {"robot_0": True, "robot_1": True}
    assert infos["robot_0"]["arrived"] and infos["robot_1"]["collided"]
    assert rewards == {"robot_0": pytest.approx(9.99), "robot_1": pytest.approx(-10.01)}
    assert env.agents == []
    parked = env.task.sim.true_poses.copy()
    env.step({})
    assert np.array_equal(env.task.sim.true_poses, parked)


def test_world_robots_become_agents_and_generated_ones_replace_them():
    assert NavigateParallelEnv(scenario="random", world="multi_robots.world").possible_agents == [
        "robot_0", "robot_1", "robot_2", "robot_3"]
    env = NavigateParallelEnv(scenario="random", n_robots=3, world="rooms.world", body=SMALL)
    assert [r.name for r in env.task.sim.robots] == ["agent_0", "agent_1", "agent_2"]
    observations, _ = env.reset(seed=0)
    assert not env.task.sim.stalled.any()
    assert observations["robot_2"].shape == (3 * 32 + 4,)


def test_the_discrete_variant_turns_table_entries_into_commands():
    env = NavigateParallelEnv(n_robots=2, body=SMALL, discrete=True)
    env.reset(seed=0)
    assert env.action_space("robot_0").n == 15
    observations, *_ = env.step({"robot_0": 14, "robot_1": 0})  # full speed turning left; standing, turning right
    assert observations["robot_0"][-2:] == pytest.approx([1.0, np.pi / 2])
    assert observations["robot_1"][-2:] == pytest.approx([0.0, -np.pi / 2])


def test_robots_with_different_lasers_cannot_share_an_observation_layout(tmp_path):
    world = tmp_path / "mixed.world"
    world.write_text(
        'include "simple_robot.inc"\n'
        'position( pose [1 1 0 0] ranger( sensor( samples 10 range [0 4] ) ) )\n'
        'simple_robot( pose [3 3 0 0] )\n'.replace("simple_robot.inc", str(_robots_folder() / "simple_robot.inc")))
    with pytest.raises(ValueError, match="lasers differ"):
        NavigateParallelEnv(scenario="random", world=str(world))


def _robots_folder():
    from stage_sim.worldfile.bundled import data_root

    return data_root() / "robots"


def test_generated_robots_join_a_world_far_from_the_origin_without_growing_its_grid(tmp_path):
    walls = "".join(
        f'model( size [{w} {h} 1] pose [{500 + x} {300 + y} 0 0] )\n'
        for x, y, w, h in ((0, 4, 8, 0.1), (0, -4, 8, 0.1), (4, 0, 0.1, 8), (-4, 0, 0.1, 8)))
    world = tmp_path / "far.world"
    world.write_text("resolution 0.05\n" + walls)
    env = NavigateParallelEnv(scenario="random", world=str(world), n_robots=2, body=SMALL)
    assert max(env.task.sim.static.shape) < 200
    env.reset(seed=0)
    assert abs(env.task.sim.true_poses[:, :2] - (500, 300)).max() < 4
