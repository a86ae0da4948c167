"""``stage_sim/Navigate-v0``: one robot of a Stage world drives to a goal (Gymnasium).

Observation and action: see :mod:`stage_sim.envs.spaces`; reward: :mod:`stage_sim.envs.task`; scenarios
and their options: :mod:`stage_sim.envs.scenarios`. Importing
:mod:`stage_sim.envs` registers the id, so ``gymnasium.make("stage_sim/Navigate-v0", world="rooms.world")``
works after it.
"""

from __future__ import annotations

from typing import Any, ClassVar

import gymnasium
import numpy as np

from stage_sim.envs.scenarios import Scenario, ScenarioOptions
from stage_sim.envs.task import NavigationTask, RewardConfig, StepResult, TaskConfig


class NavigateEnv(gymnasium.Env):
    """Robot ``robot`` of the world reaches goals drawn from free space; other robots stand still."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self, world: str | None = None, robot: int = 0, render_mode: str | None = None,
        history: int = 3, max_steps: int = 500, discrete: bool = False, reward: RewardConfig | None = None,
        **scenario: Any,
    ) -> None:
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        options = ScenarioOptions(world=world, **scenario)
        if options.scenario == "circle":
            raise ValueError("circle crossing needs several robots: use stage_sim.envs.NavigateParallelEnv")
        config = TaskConfig(history, max_steps, discrete, reward or RewardConfig())
        self.task = NavigationTask(Scenario(options), config, agents=[robot])
        self.layout = self.task.layout
        self.observation_space = self.task.observation_spaces[0]
        self.action_space = self.task.actions.space(0)
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": round(1 / self.task.sim.interval)}

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict]:
        """A new start and goal (and obstacles, in that scenario) drawn from the seeded generator."""
        super().reset(seed=seed)
        observations = self.task.reset(self.np_random)
        return observations[0], {"goal": self.task.goals[0].copy(), "distance": float(self.task.distance[0])}

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict]:
        """One simulation step with the robot commanded by ``action``."""
        result: StepResult = self.task.step(np.asarray(action)[None])
        info = {"arrived": bool(result.arrived[0]), "collided": bool(result.collided[0]),
                "distance": float(result.distance[0]), "time": self.task.steps * self.task.sim.interval}
        return (result.observations[0], float(result.rewards[0]), bool(result.terminated[0]),
                bool(result.truncated[0]), info)

    def render(self) -> np.ndarray | None:
        """The world as Stage's window shows it, an (H, W, 3) uint8 array (``render_mode="rgb_array"``)."""
        if self.render_mode != "rgb_array":
            return None
        return self.task.frame()
