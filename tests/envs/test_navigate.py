"""The single-robot Gymnasium environment as a user drives it: gymnasium.make, spaces, episodes, pictures."""

from __future__ import annotations

import math
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import stage_sim.envs  # noqa: F401  (registers stage_sim/Navigate-v0)
from stage_sim.envs import ENV_ID, NavigateEnv, RewardConfig, RobotBody
from stage_sim.envs.free_space import PlacementError
from stage_sim.envs.spaces import goal_polar
from stage_sim.worldfile.errors import WorldError

SMALL = RobotBody(laser_samples=32)


def make(**kwargs) -> NavigateEnv:
    return gymnasium.make(ENV_ID, body=SMALL, **kwargs).unwrapped


def test_check_env_passes_for_the_continuous_and_the_discrete_variant():
    # Its one remark: the Box of actions is in physical units (m/s, rad/s), not [-1, 1] (see the README).
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(gymnasium.make(ENV_ID, body=SMALL, render_mode="rgb_array").unwrapped)
    assert [str(w.message) for w in caught if "symmetric and normalized" not in str(w.message)] == []
    assert len(caught) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(gymnasium.make(ENV_ID, body=SMALL, discrete=True).unwrapped)


def test_gymnasiums_rescale_wrapper_gives_a_plus_minus_one_box_mapped_onto_the_velocity_bounds():
    low, high = np.full(2, -1.0, dtype=np.float32), np.full(2, 1.0, dtype=np.float32)
    env = gymnasium.wrappers.RescaleAction(gymnasium.make(ENV_ID, body=SMALL), low, high)
    assert env.action_space.low.tolist() == [-1.0, -1.0] and env.action_space.high.tolist() == [1.0, 1.0]
    env.reset(seed=1)
    env.step(np.array([1.0, -1.0], dtype=np.float32))
    assert env.unwrapped.task.sim.commands[0, 0] == pytest.approx(1.0)  # v_max
    assert env.unwrapped.task.sim.commands[0, 2] == pytest.approx(-math.pi / 2)  # ω_min


def test_observation_holds_k_scans_goal_and_velocity_and_actions_follow_the_velocity_bounds():
    env = make(history=2)
    assert env.observation_space.shape == (2 * 32 + 4,)
    assert env.action_space.low.tolist() == [0.0, pytest.approx(-math.pi / 2)]
    assert env.action_space.high.tolist() == [1.0, pytest.approx(math.pi / 2)]
    observation, info = env.reset(seed=3)
    distance, bearing = goal_polar(env.task.sim.true_poses[:1], info["goal"][None])
    assert observation[64] == pytest.approx(distance[0], abs=1e-5)
    assert observation[65] == pytest.approx(bearing[0], abs=1e-5)
    assert np.all((observation[:64] >= 0) & (observation[:64] <= 1))
    observation, *_ = env.step(np.array([0.5, 0.3], dtype=np.float32))
    assert observation[66:].tolist() == pytest.approx([0.5, 0.3], abs=1e-6)
    assert distance[0] >= env.task.scenario.options.min_goal_distance


def test_same_seed_same_episode_bit_for_bit_and_another_seed_another_episode():
    def episode(seed: int) -> list[np.ndarray]:
        env = make(scenario="obstacles", n_obstacles=4)
        env.action_space.seed(0)
        observation, _ = env.reset(seed=seed)
        trace = [observation]
        for _ in range(20):
            observation, reward, terminated, truncated, _ = env.step(env.action_space.sample())
            trace += [observation, np.array([reward])]
            if terminated or truncated:
                break
        return trace

    first, again, other = episode(7), episode(7), episode(8)
    assert len(first) == len(again)
    assert all(np.array_equal(a, b) for a, b in zip(first, again, strict=True))
    assert not np.array_equal(first[0], other[0])


def test_arrival_ends_the_episode_with_the_bonus_and_a_wall_ends_it_with_the_penalty():
    reward = RewardConfig(progress=0.0, arrival=5.0, collision=3.0, time=0.5, goal_tolerance=50.0)
    env = make(reward=reward)
    env.reset(seed=1)
    _, value, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))
    assert (value, terminated, truncated, info["arrived"]) == (4.5, True, False, True)

    env = make(reward=RewardConfig(progress=0.0, collision=3.0, time=0.5))
    env.reset(seed=1)
    env.task.sim.set_pose(0, 4.7, 0.0, 0.0)  # facing the east wall (inner face x = 4.95), 0.05 m off
    _, value, terminated, _, info = env.step(np.array([1.0, 0.0], dtype=np.float32))
    assert (value, terminated, info["collided"]) == (-3.5, True, True)


def test_the_step_limit_truncates():
    env = make(max_steps=3)
    env.reset(seed=2)
    ends = [env.step(np.zeros(2, dtype=np.float32))[2:4] for _ in range(3)]
    assert ends == [(False, False), (False, False), (False, True)]


def test_any_world_file_bundled_by_name_with_goals_in_the_robots_free_space():
    env = gymnasium.make(ENV_ID, world="rooms.world").unwrapped
    assert env.observation_space.shape == (3 * 240 + 4,)
    for seed in range(3):
        _, info = env.reset(seed=seed)
        assert not env.task.sim.stalled[0]
        space_ok = env.task.sim.static.collision_layer(*env.task.sim.robots[0].z_band)
        col, row = np.floor((info["goal"] - env.task.sim.static.origin_xy) / env.task.sim.static.resolution).astype(int)
        assert not space_ok[row, col]


def test_rgb_array_shows_the_world_and_the_goal():
    env = make(render_mode="rgb_array")
    env.reset(seed=4)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    from stage_sim.rendering import renderer_for

    row, col = renderer_for(env.task.sim).view().pixel(*env.task.goals[0])
    assert tuple(frame[row, col]) != tuple(frame[0, frame.shape[1] // 2])
    assert make().render() is None


def test_bad_options_say_what_is_wrong():
    with pytest.raises(ValueError, match="unknown scenario 'maze'"):
        make(scenario="maze")
    with pytest.raises(ValueError, match="several robots"):
        make(scenario="circle")
    with pytest.raises(FileNotFoundError, match="bundled worlds"):
        make(world="no_such.world")
    with pytest.raises(ValueError, match="render_mode"):
        NavigateEnv(render_mode="human", body=SMALL)
    with pytest.raises(PlacementError, match=r"cannot hold 1 robot.*larger world"):  # at construction
        make(arena_size=3.0, min_goal_distance=10.0)


def test_a_broken_world_reports_file_line_and_column(tmp_path):
    world = tmp_path / "broken.world"
    world.write_text("resolution 0.05\nmodel( size [1 1 )\n")
    with pytest.raises(WorldError, match=r"broken.world:2:"):
        make(world=str(world))


def test_in_a_world_of_several_robots_the_chosen_one_drives_and_the_others_stand_clear_of_its_start_and_goal():
    env = gymnasium.make(ENV_ID, world="multi_robots.world", robot=2, history=1).unwrapped
    others = np.array([r.start[:2] for r in env.task.sim.robots if r.index != 2])
    for seed in range(3):
        _, info = env.reset(seed=seed)
        start = env.task.sim.true_poses[2, :2]
        clearance = 2 * env.task.sim.robots[2].radius
        assert np.all(np.linalg.norm(others - start, axis=1) >= clearance)
        assert np.all(np.linalg.norm(others - info["goal"], axis=1) >= clearance)
        assert np.array_equal(env.task.sim.true_poses[[0, 1, 3], :2], others)
