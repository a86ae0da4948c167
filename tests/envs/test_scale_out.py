"""Scaling out gives the same episodes as a serial run: AsyncVectorEnv with 2 workers, the batched vector env,
Ray with 2 CPUs."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import gymnasium
import ray
from gymnasium.vector import AsyncVectorEnv

from stage_sim.envs import ENV_ID, RobotBody
from stage_sim.envs.rollouts import baseline_for, run_single, run_spec, run_vector

SMALL = RobotBody(laser_samples=32)
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "ray_sweep.py"


def make_env() -> gymnasium.Env:
    return gymnasium.make(ENV_ID, body=SMALL, scenario="obstacles", n_obstacles=4, max_steps=150)


def test_async_vector_env_with_two_workers_matches_a_serial_run():
    policy = baseline_for(make_env().unwrapped.task)
    envs = AsyncVectorEnv([make_env, make_env])
    try:
        parallel = run_vector(envs, [21, 22], policy)
    finally:
        envs.close()
    serial = [run_single(make_env(), seed, policy) for seed in (21, 22)]
    assert parallel == serial
    assert all(episode.steps > 1 for episode in serial)


def test_the_batched_vector_env_in_one_process_matches_a_serial_run():
    policy = baseline_for(make_env().unwrapped.task)
    envs = gymnasium.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point", body=SMALL,
                              scenario="obstacles", n_obstacles=4, max_steps=150)
    assert run_vector(envs, [21, 22], policy) == [run_single(make_env(), seed, policy) for seed in (21, 22)]


def test_the_ray_example_on_a_local_instance_matches_a_serial_run():
    spec = importlib.util.spec_from_file_location("ray_sweep", EXAMPLE)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    scenario = {"circle_3": {"scenario": "circle", "n_robots": 3, "body": SMALL, "max_steps": 150}}
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        distributed = example.sweep(scenario, [0, 1])
    finally:
        ray.shutdown()
    assert distributed["circle_3"] == [run_spec(scenario["circle_3"], seed) for seed in (0, 1)]
