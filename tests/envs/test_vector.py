"""The vector env as a user builds it: gymnasium.make_vec, the same episodes as N separate envs, autoreset."""

from __future__ import annotations

import gc
import tracemalloc

import gymnasium
import numpy as np
import pytest

import stage_sim.envs  # noqa: F401  (registers stage_sim/Navigate-v0)
from stage_sim.backend import KERNELS_ENV
from stage_sim.envs import ENV_ID, NavigateVectorEnv, RobotBody

SMALL = RobotBody(laser_samples=32)
# short episodes, so that every world ends (and is autoreset) several times within the steps compared
KWARGS = {"body": SMALL, "scenario": "obstacles", "n_obstacles": 4, "max_steps": 15}


def make_vector(num_envs: int, **kwargs) -> gymnasium.vector.VectorEnv:
    return gymnasium.make_vec(ENV_ID, num_envs=num_envs, vectorization_mode="vector_entry_point",
                              **{**KWARGS, **kwargs})


def test_make_vec_builds_the_batched_vector_env_with_batched_spaces():
    envs = make_vector(3)
    assert isinstance(envs, NavigateVectorEnv)
    assert envs.observation_space.shape == (3, 3 * 32 + 4)
    assert envs.action_space.shape == (3, 2)
    assert envs.metadata["autoreset_mode"] == gymnasium.vector.AutoresetMode.NEXT_STEP


@pytest.mark.parametrize("kernels", ["numpy", "numba"])
@pytest.mark.parametrize(("discrete", "scenario"), [(False, "obstacles"), (True, "obstacles"), (False, "random")])
def test_identical_step_for_step_to_n_separate_envs_with_the_same_seeds(discrete, scenario, kernels, monkeypatch):
    # The batched worlds share their base world and its free space (a world of its own per episode, or a fixed
    # world that each steps on its own): the separate envs each work theirs out. On numba the worlds step in one
    # compiled call and are scored in another; on numpy each steps and the scores are numpy's.
    monkeypatch.setenv(KERNELS_ENV, kernels)
    count = 4
    batched = make_vector(count, discrete=discrete, scenario=scenario)
    separate = gymnasium.vector.SyncVectorEnv(
        [lambda: gymnasium.make(ENV_ID, discrete=discrete, **{**KWARGS, "scenario": scenario}) for _ in range(count)])
    first, _ = batched.reset(seed=11)
    expected, _ = separate.reset(seed=11)
    assert np.array_equal(first, expected)
    batched.action_space.seed(5)
    ended = 0
    for _ in range(60):
        actions = batched.action_space.sample()
        got = batched.step(actions)
        want = separate.step(actions)
        for mine, theirs in zip(got[:4], want[:4], strict=True):
            assert mine.dtype == theirs.dtype
            assert np.array_equal(mine, theirs)
        ended += int(np.sum(got[2] | got[3]))
        assert batched.unwrapped._batch.whole == (kernels == "numba")
    assert ended >= count  # the comparison went through autoresets, not just one episode per world
    # a reset with a list of seeds, then more steps: still the same
    assert np.array_equal(batched.reset(seed=[3, 1, 4, 1])[0], separate.reset(seed=[3, 1, 4, 1])[0])
    actions = batched.action_space.sample()
    assert all(np.array_equal(a, b) for a, b in zip(batched.step(actions)[:4], separate.step(actions)[:4],
                                                    strict=True))


def test_an_ended_world_is_reset_by_the_next_step_with_reward_zero():
    envs = make_vector(2, max_steps=3)
    envs.reset(seed=0)
    still = np.zeros((2, 2), dtype=np.float32)
    for _ in range(3):
        _, rewards, terminated, truncated, infos = envs.step(still)
    assert truncated.tolist() == [True, True] and not terminated.any()
    observations, rewards, terminated, truncated, infos = envs.step(still)
    assert rewards.tolist() == [0.0, 0.0] and not (terminated | truncated).any()
    assert infos["_goal"].tolist() == [True, True] and not infos["_arrived"].any()
    assert observations in envs.observation_space


def test_batches_have_the_dtypes_gymnasium_vector_envs_use_and_lie_in_the_spaces():
    # Gymnasium 1.4 has no checker for vector envs (check_env takes single envs only): the contract by hand.
    envs = make_vector(2)
    observations, _ = envs.reset(seed=0)
    assert observations in envs.observation_space
    observations, rewards, terminated, truncated, _ = envs.step(envs.action_space.sample())
    assert observations in envs.observation_space
    assert (rewards.dtype, terminated.dtype, truncated.dtype) == (np.float64, np.bool_, np.bool_)
    assert rewards.shape == terminated.shape == truncated.shape == (2,)


def assert_same_infos(mine: dict, theirs: dict) -> None:
    """The same keys, masks and (where masked in) values, recursively."""
    assert set(mine) == set(theirs)
    for key, value in theirs.items():
        if isinstance(value, dict):
            assert_same_infos(mine[key], value)
        elif key.startswith("_"):
            assert np.array_equal(mine[key], value), key
        elif key == "final_obs":
            for world in np.flatnonzero(theirs["_final_obs"]):
                assert np.array_equal(mine[key][world], value[world])
        else:
            mask = theirs[f"_{key}"]
            assert mine[key].dtype == value.dtype, key
            assert np.array_equal(mine[key][mask], value[mask]), key


@pytest.mark.parametrize("kernels", ["numpy", "numba"])
def test_same_step_autoreset_is_sync_vector_envs_step_for_step_infos_included(kernels, monkeypatch):
    """What Stable-Baselines3 and older libraries expect: the step that ends an episode returns the next
    one's first observation, the last in infos["final_obs"]."""
    monkeypatch.setenv(KERNELS_ENV, kernels)
    count, same_step = 3, gymnasium.vector.AutoresetMode.SAME_STEP
    batched = make_vector(count, autoreset_mode="SameStep")
    assert batched.metadata["autoreset_mode"] == same_step
    separate = gymnasium.vector.SyncVectorEnv(
        [lambda: gymnasium.make(ENV_ID, **KWARGS) for _ in range(count)], autoreset_mode=same_step)
    assert np.array_equal(batched.reset(seed=7)[0], separate.reset(seed=7)[0])
    batched.action_space.seed(2)
    ended = 0
    for _ in range(50):
        actions = batched.action_space.sample()
        got, want = batched.step(actions), separate.step(actions)
        for mine, theirs in zip(got[:4], want[:4], strict=True):
            assert mine.dtype == theirs.dtype and np.array_equal(mine, theirs)
        assert_same_infos(got[4], want[4])
        ended += int(np.sum(got[2] | got[3]))
        assert batched.unwrapped._batch.whole == (kernels == "numba")
    assert ended >= count


def test_an_unknown_autoreset_mode_is_refused():
    with pytest.raises(ValueError, match="NextStep or SameStep, got Disabled"):
        make_vector(2, autoreset_mode="Disabled")


@pytest.mark.parametrize(("scenario", "bound"), [("obstacles", 1.3e6), ("random", 0.15e6)])
def test_a_world_more_costs_the_memory_of_its_episode_not_of_a_base_world(scenario, bound, monkeypatch):
    # What depends on the base world alone (its simulation, its free space: dense grids of a 30 m arena at 5 cm)
    # is held once for all worlds: before, each world held its own, 13 MB (obstacles) and 5 MB (random) a world.
    # A world of the random scenario is the base world itself: its raster, casters and free space are the
    # base's, and it holds only its robot's state and scratch (44 kB; 942 kB when each made its own). An
    # episode's free space holds what its obstacles took from the base's, not grids of the whole arena (1.1 MB
    # a world; 1.7 MB when it kept its own blocked and valid grids).
    # On the compiled kernels from the first step (without a choice the first worlds of a process start on numpy,
    # whose tables are others).
    monkeypatch.setenv("STAGE_SIM_KERNELS", "numba")
    def held(count: int) -> int:
        gc.collect()
        tracemalloc.start()
        try:
            envs = NavigateVectorEnv(count, scenario=scenario, n_obstacles=8, arena_size=30.0, body=SMALL)
            envs.reset(seed=0)
            for _ in range(5):
                envs.step(np.full((count, 2), 0.5, dtype=np.float32))
            gc.collect()
            return tracemalloc.get_traced_memory()[0]
        finally:
            tracemalloc.stop()

    held(1)  # the kernels loaded, outside the count
    per_world = (held(9) - held(3)) / 6
    assert per_world < bound, f"{per_world / 1e6:.2f} MB a world"
