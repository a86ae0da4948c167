"""N robots of one world reach their goals together (PettingZoo ``ParallelEnv``).

Agents are named ``robot_<i>`` after their robot's index in the world (stageros' naming). Each has the
observation, action and reward of :class:`stage_sim.envs.NavigateEnv`; all robots move in one simulation
step. An agent that arrives or collides leaves the episode (its robot stops and stays as an obstacle);
the episode is over when no agent is left or at the step limit.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from stage_sim.envs.scenarios import Scenario, ScenarioOptions
from stage_sim.envs.task import NavigationTask, RewardConfig, TaskConfig

#: Robots generated when neither ``n_robots`` nor a world with robots says how many.
DEFAULT_ROBOTS = 4


class NavigateParallelEnv(ParallelEnv):
    """Every robot of a scenario's world is an agent: ``n_robots`` generated ones, else the world's own (a
    generated arena or the circle gets :data:`DEFAULT_ROBOTS`)."""

    metadata: ClassVar[dict[str, Any]] = {
        "name": "stage_sim_navigate_v0", "render_modes": ["rgb_array"], "is_parallelizable": True}

    def __init__(
        self, scenario: str = "circle", n_robots: int | None = None, render_mode: str | None = None,
        history: int = 3, max_steps: int = 500, discrete: bool = False, reward: RewardConfig | None = None,
        **options: Any,
    ) -> None:
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        config = TaskConfig(history, max_steps, discrete, reward or RewardConfig())
        if n_robots is None and (scenario == "circle" or options.get("world") is None):
            n_robots = DEFAULT_ROBOTS
        self.task = NavigationTask(Scenario(ScenarioOptions(scenario=scenario, n_robots=n_robots, **options)), config)
        self.layout = self.task.layout
        self.possible_agents = [f"robot_{i}" for i in self.task.agents]
        self._index = {name: k for k, name in enumerate(self.possible_agents)}
        self.observation_spaces = dict(zip(self.possible_agents, self.task.observation_spaces, strict=True))
        self.action_spaces = {name: self.task.actions.space(k) for name, k in self._index.items()}
        self.agents: list[str] = []
        self.render_mode = render_mode
        self._rng = np.random.default_rng()
        first = self.action_spaces[self.possible_agents[0]]
        self._idle = np.zeros((len(self.possible_agents), *first.shape), dtype=first.dtype)

    def observation_space(self, agent: str) -> spaces.Space:
        """The space of ``agent``'s observations."""
        return self.observation_spaces[agent]

    def action_space(self, agent: str) -> spaces.Space:
        """The space of ``agent``'s actions."""
        return self.action_spaces[agent]

    def reset(self, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        """A new episode; a seed fixes it (and the ones after it, if later resets give none)."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        observations = self.task.reset(self._rng)
        self.agents = list(self.possible_agents)
        infos = {name: {"goal": self.task.goals[k].copy()} for name, k in self._index.items()}
        return {name: observations[k] for name, k in self._index.items()}, infos

    def step(self, actions: dict[str, Any]) -> tuple[dict, dict, dict, dict, dict]:
        """One simulation step for all agents; agents missing from ``actions`` stand still."""
        batch = self._idle.copy()
        for name, action in actions.items():
            batch[self._index[name]] = action
        result = self.task.step(batch)
        live = [(name, self._index[name]) for name in self.agents]
        time = self.task.steps * self.task.sim.interval
        observations = {name: result.observations[k] for name, k in live}
        rewards = {name: float(result.rewards[k]) for name, k in live}
        terminated = {name: bool(result.terminated[k]) for name, k in live}
        truncated = {name: bool(result.truncated[k]) for name, k in live}
        infos = {name: {"arrived": bool(result.arrived[k]), "collided": bool(result.collided[k]),
                        "distance": float(result.distance[k]), "time": time} for name, k in live}
        self.agents = [name for name, k in live if self.task.active[k]]
        return observations, rewards, terminated, truncated, infos

    def render(self) -> np.ndarray | None:
        """The world with every goal marked, an (H, W, 3) uint8 array (``render_mode="rgb_array"``)."""
        if self.render_mode != "rgb_array":
            return None
        return self.task.frame()

    def state(self) -> np.ndarray:
        """Global state: every agent's true pose (x, y, yaw) and goal (x, y), one row each, flattened."""
        poses = self.task.sim.true_poses[self.task.agents]
        return np.concatenate([poses, self.task.goals], axis=1).astype(np.float32).ravel()
