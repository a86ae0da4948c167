"""N independent one-robot worlds as one PettingZoo ``ParallelEnv``: the vector env for multi-agent libraries.

Agent ``world_<i>`` is the robot of world i, a world of :class:`~stage_sim.envs.NavigateEnv` (same keyword
arguments); the worlds do not see each other. All worlds are stepped and scored together by
:class:`~stage_sim.envs.NavigateVectorEnv`'s batched step; an agent whose episode ends leaves (its world
stands still) and the episode is over when no agent is left. ``reset(seed=s)`` seeds world i with ``s + i``,
so agent ``world_<i>`` lives the episodes ``NavigateEnv`` reset with seed ``s + i`` would.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from stage_sim.envs.vector import NavigateVectorEnv


class NavigateParallelVectorEnv(ParallelEnv):
    """``num_worlds`` one-robot worlds, one agent each, stepped together."""

    metadata: ClassVar[dict[str, Any]] = {"name": "stage_sim_navigate_worlds_v0", "render_modes": [],
                                          "is_parallelizable": True}

    def __init__(self, num_worlds: int, **kwargs: Any) -> None:
        self.worlds = NavigateVectorEnv(num_worlds, **kwargs)
        self.layout = self.worlds.layout
        self.possible_agents = [f"world_{i}" for i in range(num_worlds)]
        self._index = {name: i for i, name in enumerate(self.possible_agents)}
        self.agents: list[str] = []
        self.render_mode = None
        space = self.worlds.single_action_space
        self._idle = np.zeros((num_worlds, *space.shape), dtype=space.dtype)
        self._live = np.zeros(num_worlds, dtype=bool)

    def observation_space(self, agent: str) -> spaces.Space:
        """Every agent's observation space (the worlds' robots are alike)."""
        return self.worlds.single_observation_space

    def action_space(self, agent: str) -> spaces.Space:
        """Every agent's action space."""
        return self.worlds.single_action_space

    def reset(self, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        """Every world anew (world i seeded with ``seed + i``; without a seed each goes on with its generator)."""
        observations, infos = self.worlds.reset(seed=seed)
        self.agents = list(self.possible_agents)
        self._live[:] = True
        return ({name: observations[i] for i, name in enumerate(self.agents)},
                {name: {"goal": infos["goal"][i]} for i, name in enumerate(self.agents)})

    def step(self, actions: dict[str, Any]) -> tuple[dict, dict, dict, dict, dict]:
        """One step of every live agent's world; agents missing from ``actions`` stand still."""
        batch = self._idle.copy()
        for name, action in actions.items():
            batch[self._index[name]] = action
        result = self.worlds.advance(batch, self._live.copy())
        live = [(name, self._index[name]) for name in self.agents]
        times = self.worlds.steps * self.worlds.interval
        observations = {name: result.observations[i] for name, i in live}
        rewards = {name: float(result.rewards[i]) for name, i in live}
        terminated = {name: bool(result.terminated[i]) for name, i in live}
        truncated = {name: bool(result.truncated[i]) for name, i in live}
        infos = {name: {"arrived": bool(result.arrived[i]), "collided": bool(result.collided[i]),
                        "distance": float(result.distance[i]), "time": float(times[i])} for name, i in live}
        self._live &= ~(result.terminated | result.truncated)
        self.agents = [name for name, i in live if self._live[i]]
        return observations, rewards, terminated, truncated, infos
