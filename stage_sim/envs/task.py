"""The navigation task both environments wrap: A agents of one simulation, stepped and scored as arrays.

One :meth:`NavigationTask.step` commands every active agent, advances the simulation once (all robots move
and all lasers are cast in that one call) and computes observations, rewards and episode ends for all
agents with array operations. Agents whose episode ended stand still and stay in the world as obstacles.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from stage_sim.envs.actions import ActionMap
from stage_sim.envs.observation import ObservationBuilder, goal_polar, layout_for
from stage_sim.envs.reward import RewardConfig, score
from stage_sim.envs.scenarios import Scenario
from stage_sim.sim.simulation import Simulation

#: Seeds handed to the simulation are drawn below this bound from the episode's generator.
SEED_BOUND = 2**63


@dataclass(frozen=True)
class TaskConfig:
    """How episodes are observed, acted in, scored and cut short."""

    history: int = 3
    max_steps: int = 500
    discrete: bool = False
    reward: RewardConfig = field(default_factory=RewardConfig)

    def __post_init__(self) -> None:
        if self.history < 1 or self.max_steps < 1:
            raise ValueError(f"history and max_steps must be at least 1, got {self.history} and {self.max_steps}")


@dataclass
class StepResult:
    """Per agent (A,) arrays of one step; ``active`` tells which agents were still in the episode."""

    observations: np.ndarray
    rewards: np.ndarray
    terminated: np.ndarray
    truncated: np.ndarray
    arrived: np.ndarray
    collided: np.ndarray
    distance: np.ndarray
    active: np.ndarray


class NavigationTask:
    """Episodes of ``scenario`` for the robots ``agents`` (default: every robot of the world)."""

    def __init__(self, scenario: Scenario, config: TaskConfig, agents: list[int] | None = None) -> None:
        self.scenario = scenario
        self.config = config
        self._base = Simulation(scenario.base)
        self.sim = self._base
        self.agents = list(range(len(self._base.robots))) if agents is None else list(agents)
        bad = [a for a in self.agents if not 0 <= a < len(self._base.robots)]
        if bad or not self.agents:
            raise ValueError(f"no robot {bad or '(none chosen)'} in a world of {len(self._base.robots)} robots")
        self.layout = layout_for(self._base, self.agents, config.history)
        bounds = np.array([self._base.robots[a].settings.velocity_bounds for a in self.agents])
        self.actions = ActionMap(bounds, config.discrete)
        self.observation_spaces = [self.layout.space(b) for b in bounds]
        self._observer = ObservationBuilder(self.layout, self.agents, self.observation_spaces)
        count = len(self.agents)
        self.goals = np.zeros((count, 2))
        self.active = np.zeros(count, dtype=bool)
        self.distance = np.zeros(count)
        self.steps = 0

    def reset(self, rng: np.random.Generator) -> np.ndarray:
        """A new episode drawn from ``rng``; returns the (A, D) first observations."""
        if self.scenario.changes_world:
            self.sim = Simulation(self.scenario.world(rng, self._base))
        self.sim.reset(int(rng.integers(SEED_BOUND)))
        starts, self.goals = self.scenario.place(self.sim, self.agents, rng)
        for agent, start in zip(self.agents, starts, strict=True):
            self.sim.set_pose(agent, *start)
        # set_pose defers the lasers to the next step: one still step scans from the placed poses.
        self.sim.step()
        self._observer.reset(self.sim)
        self.active[:] = True
        self.steps = 0
        self.distance = goal_polar(self.sim.true_poses[self.agents], self.goals)[0]
        return self._observer.rows(self.sim, self.goals)

    def step(self, actions: np.ndarray) -> StepResult:
        """Apply one action per agent (those of finished agents are ignored) and advance one step."""
        commands = self.actions.commands(actions) * self.active[:, None]
        for agent, (forward, turn) in zip(self.agents, commands, strict=True):
            self.sim.set_velocity(agent, float(forward), 0.0, float(turn))
        self.sim.step()
        self.steps += 1
        observations = self._observer.observe(self.sim, self.goals)
        before = self.distance
        self.distance = goal_polar(self.sim.true_poses[self.agents], self.goals)[0]
        outcome = score(self.config.reward, before, self.distance, self.sim.stalled[self.agents])
        active = self.active.copy()
        terminated = (outcome.arrived | outcome.collided) & active
        truncated = ~terminated & active & (self.steps >= self.config.max_steps)
        self.active &= ~(terminated | truncated)
        return StepResult(observations, outcome.reward * active, terminated, truncated,
                          outcome.arrived & active, outcome.collided & active, self.distance, active)
