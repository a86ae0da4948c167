"""Train Stable-Baselines3 PPO on ``stage_sim/Navigate-v0``'s obstacles scenario and record its learning curve.

One robot (512-beam 180° 4 m lidar, the env's own observation and reward) drives to goals in a 10 × 10 m
arena with 8 boxes drawn anew every episode. Training steps ``--envs`` worlds together in stage_sim's batched
vector env (``gymnasium.make_vec``, same-step autoreset, the form SB3 expects), seen by SB3 through
:class:`SB3VecEnv`, a thin adapter to its ``VecEnv`` interface (SB3 2.x takes no Gymnasium vector env).
Every ``--eval-every`` env steps the deterministic policy runs ``--eval-episodes`` episodes on seeds
training never used, and at the end ``--final-episodes`` more. Each evaluation is one JSON line (env steps,
success rate, collision rate, wall time) written to ``--out``; the docs draw the learning curve from it
(tools/docs_tables.py). ``make train`` runs this in ``.venv-train`` (the ``train``
extra: stable-baselines3 and a CPU torch)::

    .venv-train/bin/python examples/train_ppo.py                       # the documented run
    .venv-train/bin/python examples/train_ppo.py --steps 4096 --eval-every 2048 --eval-episodes 2 \\
        --final-episodes 2 --out /tmp/curve.jsonl                      # a smoke run
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import torch
from gymnasium.vector import AutoresetMode
from gymnasium.wrappers import RescaleAction
from gymnasium.wrappers.vector import RescaleAction as RescaleVectorAction
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import VecEnv, VecMonitor

import stage_sim.envs  # noqa: F401  (registers stage_sim/Navigate-v0)

ENV_KWARGS: dict[str, Any] = {"scenario": "obstacles", "n_obstacles": 8}
#: Evaluation seeds start here; training episodes are seeded 0..n_envs-1 and then run on from those
#: generators, so no evaluation episode is one the policy trained on.
EVAL_SEED = 1_000_000


def make_env(discrete: bool) -> gymnasium.Env:
    """The env as the policy sees it: continuous actions rescaled to [-1, 1] (SB3's Gaussian starts centred
    on 0 with unit spread; on the env's own [0, 1] m/s forward range, half its draws and a deterministic mean
    at 0 would clip to standing still), or the env's own discrete action set."""
    env = gymnasium.make("stage_sim/Navigate-v0", discrete=discrete, **ENV_KWARGS)
    return env if discrete else RescaleAction(env, -1.0, 1.0)


def make_vector_env(envs: int, discrete: bool) -> gymnasium.vector.VectorEnv:
    """``envs`` worlds of :func:`make_env`'s env, stepped together, ended episodes reset within their step."""
    vector = gymnasium.make_vec("stage_sim/Navigate-v0", num_envs=envs, discrete=discrete,
                                autoreset_mode=AutoresetMode.SAME_STEP, **ENV_KWARGS)
    return vector if discrete else RescaleVectorAction(vector, -1.0, 1.0)


class SB3VecEnv(VecEnv):
    """A Gymnasium 1.x vector env with same-step autoreset as SB3's ``VecEnv``: per-world info dicts, the last
    observation of an ended episode as ``terminal_observation``, a time limit as ``TimeLimit.truncated``."""

    def __init__(self, env: gymnasium.vector.VectorEnv) -> None:
        if env.metadata.get("autoreset_mode") != AutoresetMode.SAME_STEP:
            raise ValueError("SB3 needs same-step autoreset: make the vector env with autoreset_mode=SAME_STEP")
        self.env = env
        super().__init__(env.num_envs, env.single_observation_space, env.single_action_space)
        self._actions: np.ndarray | None = None

    def reset(self) -> np.ndarray:
        seeds = None if self._seeds[0] is None else list(self._seeds)
        observations, _ = self.env.reset(seed=seeds)
        self._reset_seeds()
        return observations

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        observations, rewards, terminated, truncated, infos = self.env.step(self._actions)
        return observations, rewards, terminated | truncated, self._per_world(infos, terminated, truncated)

    def _per_world(self, infos: dict[str, Any], terminated: np.ndarray, truncated: np.ndarray) -> list[dict]:
        """Gymnasium's batched infos (a value array and a ``_key`` mask per key) as one dict per world, an
        ended world's being its last step's (``final_info``)."""
        def unbatch(batched: dict[str, Any], world: int) -> dict[str, Any]:
            return {key: value[world] for key, value in batched.items()
                    if not key.startswith("_") and key not in ("final_obs", "final_info")
                    and batched.get(f"_{key}", np.zeros(self.num_envs, bool))[world]}

        worlds = []
        for world in range(self.num_envs):
            if terminated[world] or truncated[world]:
                info = unbatch(infos["final_info"], world)
                info["terminal_observation"] = infos["final_obs"][world]
                info["TimeLimit.truncated"] = bool(truncated[world] and not terminated[world])
            else:
                info = unbatch(infos, world)
            worlds.append(info)
        return worlds

    def close(self) -> None:
        self.env.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        return [getattr(self.env, attr_name)] * len(self._get_indices(indices))

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        setattr(self.env, attr_name, value)

    def env_method(self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any) -> list:
        return [getattr(self.env, method_name)(*method_args, **method_kwargs)] * len(self._get_indices(indices))

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [False] * len(self._get_indices(indices))


def evaluate(model: PPO, episodes: int, first_seed: int, discrete: bool) -> dict[str, float]:
    """Success and collision rates of the deterministic policy over ``episodes`` seeded episodes."""
    env = make_env(discrete)
    arrived = collided = 0
    for seed in range(first_seed, first_seed + episodes):
        observation, _ = env.reset(seed=seed)
        done = False
        while not done:
            action, _ = model.predict(observation, deterministic=True)
            observation, _, terminated, truncated, info = env.step(action)
            done = terminated or truncated
        arrived += info["arrived"]
        collided += info["collided"]
    env.close()
    return {"episodes": episodes, "success_rate": arrived / episodes, "collision_rate": collided / episodes}


class Curve(BaseCallback):
    """Evaluates every ``every`` env steps and appends one JSON line per evaluation to ``out``."""

    def __init__(self, out: Path, every: int, episodes: int, started: float, discrete: bool) -> None:
        super().__init__()
        self.out, self.every, self.episodes, self.started = out, every, episodes, started
        self.discrete = discrete
        self.next_eval = every
        self.round = 0

    def record(self, line: dict[str, Any]) -> None:
        text = json.dumps({"env_steps": self.num_timesteps, **line,
                           "wall_s": round(time.perf_counter() - self.started, 1)})
        print(text, flush=True)
        with self.out.open("a") as stream:
            stream.write(text + "\n")

    def _on_step(self) -> bool:
        if self.num_timesteps >= self.next_eval:
            self.next_eval += self.every
            # Each evaluation gets its own seeds, all unseen in training.
            result = evaluate(self.model, self.episodes, EVAL_SEED + 10_000 * self.round, self.discrete)
            self.round += 1
            self.record(result)
        return True


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=800_000, help="training budget in env steps")
    parser.add_argument("--envs", type=int, default=8, help="worlds of the vector env, stepped together")
    parser.add_argument("--eval-every", type=int, default=40_000, help="env steps between evaluations")
    parser.add_argument("--eval-episodes", type=int, default=30)
    parser.add_argument("--final-episodes", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--discrete", action="store_true", help="the env's discrete actions (15) instead of continuous")
    parser.add_argument("--out", type=Path, default=Path("docs/data/train/ppo_obstacles.jsonl"))
    parser.add_argument("--save", type=Path, default=None, help="where to save the trained policy (.zip)")
    args = parser.parse_args(argv)

    torch.set_num_threads(1)  # one core: the env and the network take turns, threads would only contend
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("")
    started = time.perf_counter()
    envs = VecMonitor(SB3VecEnv(make_vector_env(args.envs, args.discrete)))  # episode returns for SB3's log
    envs.seed(args.seed)  # world i starts from seed + i, as SB3's make_vec_env seeds its envs
    model = PPO("MlpPolicy", envs, n_steps=256, batch_size=256, n_epochs=5, learning_rate=3e-4, gamma=0.99,
                gae_lambda=0.95, ent_coef=0.0, clip_range=0.2,
                policy_kwargs={"net_arch": [256, 256]}, seed=args.seed, verbose=0, device="cpu")
    curve = Curve(args.out, args.eval_every, args.eval_episodes, started, args.discrete)
    model.learn(total_timesteps=args.steps, callback=curve)
    if args.save:
        model.save(args.save)
    final = evaluate(model, args.final_episodes, EVAL_SEED - args.final_episodes, args.discrete)
    curve.record({**final, "final": True})
    return 0


if __name__ == "__main__":
    sys.exit(main())
