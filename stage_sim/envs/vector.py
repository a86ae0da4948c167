"""``stage_sim/Navigate-v0`` as a Gymnasium ``VectorEnv``: N independent one-robot worlds in one process.

``gymnasium.make_vec("stage_sim/Navigate-v0", num_envs=N, vectorization_mode="vector_entry_point")`` (the
default mode for this id) builds it. World i is what ``gymnasium.make("stage_sim/Navigate-v0", ...)`` would
be, seeded with ``seed + i`` (or ``seed[i]``), and the vector env is identical to N such envs in a
``SyncVectorEnv`` step for step, but it does the task's work (commands, observations, rewards, episode ends)
once for all worlds as arrays instead of once per world, and the worlds' simulation steps in one compiled call
(:class:`~stage_sim.sim.simulation.SimulationBatch`, which holds the worlds' state between steps: read a
world's simulation through :meth:`NavigateVectorEnv.simulation`); on the compiled kernels the observations,
rewards and episode ends of all worlds are one compiled call too (:func:`~stage_sim.envs.task.compiled_finish_rows`).

Autoreset is Gymnasium 1.x's default, next-step: a world whose episode ended in one step is reset by the
next ``step`` (its action ignored), which returns the new episode's first observation with reward 0 and
neither terminated nor truncated. ``autoreset_mode=AutoresetMode.SAME_STEP`` (or ``"SameStep"``: what
Stable-Baselines3 and other libraries that predate Gymnasium 1.0 expect) resets it within the step that ended
it instead: that step returns the new episode's first observation, and the last one in ``infos["final_obs"]``
(with its infos in ``infos["final_info"]``), as ``SyncVectorEnv(..., autoreset_mode=AutoresetMode.SAME_STEP)``
does.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from stage_sim.envs.scenarios import Scenario, ScenarioOptions
from stage_sim.envs.spaces import ActionMap, ObservationBuilder, first_laser_ranges, goal_polar
from stage_sim.envs.task import (
    NavigationTask,
    RewardConfig,
    StepResult,
    TaskConfig,
    compiled_finish_rows,
    score,
    step_result,
)
from stage_sim.sim.simulation import Simulation, SimulationBatch


class NavigateVectorEnv(gymnasium.vector.VectorEnv):
    """``num_envs`` worlds of :class:`~stage_sim.envs.NavigateEnv` (same keyword arguments), stepped together."""

    metadata: dict[str, Any] = {"autoreset_mode": gymnasium.vector.AutoresetMode.NEXT_STEP}  # noqa: RUF012

    def __init__(
        self, num_envs: int, world: str | None = None, robot: int = 0, history: int = 3, max_steps: int = 500,
        discrete: bool = False, reward: RewardConfig | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP, **scenario: Any,
    ) -> None:
        if num_envs < 1:
            raise ValueError(f"num_envs must be at least 1, got {num_envs}")
        self.autoreset_mode = AutoresetMode(autoreset_mode)
        if self.autoreset_mode not in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
            raise ValueError(f"autoreset_mode must be NextStep or SameStep, got {self.autoreset_mode.value}")
        self.metadata = {**self.metadata, "autoreset_mode": self.autoreset_mode}
        options = ScenarioOptions(world=world, **scenario)
        if options.scenario == "circle":
            raise ValueError("circle crossing needs several robots: use stage_sim.envs.NavigateParallelEnv")
        self.config = TaskConfig(history, max_steps, discrete, reward or RewardConfig())
        scenario = Scenario(options)  # the base world, its simulation and free space: one for all worlds
        self._tasks = [NavigationTask(scenario, self.config, agents=[robot]) for _ in range(num_envs)]
        self._sims = [task.sim for task in self._tasks]  # each world's simulation: held by the batch between steps
        self._every_world = list(range(num_envs))
        first = self._tasks[0]
        self.num_envs = num_envs
        self.robot = robot
        self.layout = first.layout
        self.single_observation_space = first.observation_spaces[0]
        self.single_action_space = first.actions.space(0)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        bounds = np.array([first.sim.robots[robot].settings.velocity_bounds] * num_envs, dtype=np.float64)
        self.actions = ActionMap(bounds, discrete)
        self._observer = ObservationBuilder(self.layout, [robot] * num_envs, [self.single_observation_space] * num_envs)
        self._rngs: list[np.random.Generator | None] = [None] * num_envs
        self.goals = np.zeros((num_envs, 2))
        self.distance = np.zeros(num_envs)
        self.steps = np.zeros(num_envs, dtype=np.int64)
        self._autoreset = np.zeros(num_envs, dtype=bool)
        self.interval = first.sim.interval  #: sim seconds a step
        self._batch = SimulationBatch(num_envs)  # the worlds' steps in one compiled call
        self._beams = first.sim.beams_of(robot)  # the robot's first ranger among the beams

    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Every world anew; world i seeded with ``seed + i`` (an int) or ``seed[i]`` (a list), as
        ``SyncVectorEnv`` seeds its sub-environments; without a seed each world goes on with its generator."""
        if seed is None:
            seeds: list[int | None] = [None] * self.num_envs
        elif isinstance(seed, int):
            seeds = [seed + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"{len(seeds)} seeds for {self.num_envs} worlds")
        rows = np.empty((self.num_envs, self.layout.size), dtype=np.float32)
        for world, world_seed in enumerate(seeds):
            rows[world] = self._reset_world(world, world_seed)
        self._autoreset[:] = False
        return rows, {"goal": self.goals.copy(), "_goal": np.ones(self.num_envs, dtype=bool)}

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One step of every world; next-step autoreset: worlds whose episode ended at the last step are reset
        instead; same-step: worlds whose episode ends in this one are reset after it."""
        if self.autoreset_mode is AutoresetMode.SAME_STEP:
            return self._step_and_reset(actions)
        restart = self._autoreset.copy()
        moving = ~restart
        result = self.advance(actions, moving)
        observations = result.observations
        for world in np.flatnonzero(restart):
            observations[world] = self._reset_world(world, None)
        self._autoreset = result.terminated | result.truncated
        infos = {"arrived": result.arrived, "collided": result.collided, "distance": self.distance.copy(),
                 "time": self.steps * self.interval}
        infos.update({f"_{key}": moving.copy() for key in list(infos)})
        if restart.any():
            infos["goal"], infos["_goal"] = self.goals.copy(), restart
        return observations, result.rewards, result.terminated, result.truncated, infos

    def _step_and_reset(
        self, actions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Same-step autoreset, with the infos ``SyncVectorEnv`` gathers: an ended world's step infos under
        ``final_info`` and its last observation in ``final_obs``, its reset infos (goal, distance) at the top."""
        everyone = np.ones(self.num_envs, dtype=bool)
        result = self.advance(actions, everyone)
        observations = result.observations
        ended = result.terminated | result.truncated
        going = ~ended
        stepped = {"arrived": result.arrived, "collided": result.collided, "distance": self.distance.copy(),
                   "time": self.steps * self.interval}
        infos: dict[str, Any] = {}
        if going.any():  # a key only when some world has it, as SyncVectorEnv gathers them
            for key, values in stepped.items():
                infos[key], infos[f"_{key}"] = np.where(going, values, np.zeros_like(values)), going.copy()
        if ended.any():
            final_obs = np.full(self.num_envs, None, dtype=object)
            final_info: dict[str, Any] = {}
            for key, values in stepped.items():
                final_info[key], final_info[f"_{key}"] = np.where(ended, values, np.zeros_like(values)), ended.copy()
            for world in np.flatnonzero(ended):
                final_obs[world] = observations[world].copy()
                observations[world] = self._reset_world(world, None)
            infos["final_obs"], infos["_final_obs"] = final_obs, ended.copy()
            infos["final_info"], infos["_final_info"] = final_info, ended.copy()
            infos["goal"], infos["_goal"] = np.where(ended[:, None], self.goals, 0.0), ended.copy()
            infos["distance"] = np.where(ended, self.distance, infos.get("distance", 0.0))
            infos["_distance"] = everyone
        return observations, result.rewards, result.terminated, result.truncated, infos

    def advance(self, actions: np.ndarray, moving: np.ndarray) -> StepResult:
        """Step the worlds in ``moving`` (the others stand) and score them as arrays: (W,) results, nothing
        for the worlds that stood. No reset: whoever calls it decides what an ended episode leads to."""
        chosen = self.actions.commands(actions)
        robot, batch = self.robot, self._batch
        commands = np.zeros((self.num_envs, 3))  # (forward, sideways, turn) of each world's robot
        commands[:, 0], commands[:, 2] = chosen[:, 0], chosen[:, 1]
        if moving.all():
            batch.step(self._sims, self._every_world, commands, robot)
        else:
            worlds = np.flatnonzero(moving)
            batch.step([self._sims[world] for world in worlds.tolist()], worlds.tolist(), commands[worlds], robot)
        self.steps += moving
        at_limit = self.steps >= self.config.max_steps
        # Compiled worlds, all stepped in the batch's call: scored in one compiled pass from the state it holds of
        # them (the worlds that stood keep their rows as they were, and are reset next).
        if batch.whole:
            result = compiled_finish_rows(
                self._observer, self.config.reward, batch.ranges[:, self._beams], batch.poses[:, robot],
                batch.velocities[:, robot], batch.stalled[:, robot], self.goals, self.distance, moving.copy(), at_limit)
            self.distance = result.distance
            return result
        batch.sync()  # the worlds that did join are read from their simulations too
        sims = self._sims
        poses = np.array([sim.true_poses[robot] for sim in sims])
        ranges = np.concatenate([first_laser_ranges(sim, np.array([robot])) for sim in sims])
        velocity = np.array([sim.velocities[robot] for sim in sims])
        stalled = np.array([sim.stalled[robot] for sim in sims])
        before = self.distance
        distance, bearing = goal_polar(poses, self.goals)
        observations = self._observer.observe_arrays(ranges, velocity, distance, bearing)
        outcome = score(self.config.reward, before, distance, stalled)
        self.distance = distance
        return step_result(outcome, observations, distance, moving, at_limit)

    def simulation(self, world: int) -> Simulation:
        """World ``world``'s simulation, up to date (the batch holds the worlds' state between steps). It may be
        read, and changed between steps as a user of :class:`~stage_sim.sim.simulation.Simulation` would."""
        self._batch.sync([world])
        return self._sims[world]

    def _reset_world(self, world: int, seed: int | None) -> np.ndarray:
        """Reset world ``world`` as ``NavigateEnv.reset(seed=seed)`` would and return its first observation."""
        if seed is not None or self._rngs[world] is None:
            self._rngs[world], _ = seeding.np_random(seed)
        task = self._tasks[world]
        self._batch.sync([world])  # its simulation as its steps left it, before the reset changes it
        observation = task.reset(self._rngs[world])[0]
        self._sims[world] = task.sim
        self.goals[world] = task.goals[0]
        self.distance[world] = task.distance[0]
        self.steps[world] = 0
        self._observer.restore(world, observation)
        return observation
