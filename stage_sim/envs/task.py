"""The navigation task both environments wrap: A agents of one simulation, stepped and scored as arrays.

One :meth:`NavigationTask.step` commands every active agent, advances the simulation once (all robots move
and all lasers are cast in that one call) and computes observations, rewards and episode ends for all
agents with array operations. Agents whose episode ended stand still and stay in the world as obstacles.

Reward per agent per step:
``progress · (d_before − d_after) + arrival · [arrived] − collision · [collided] − time``, d the distance to
the goal; an agent has *arrived* when d ≤ ``goal_tolerance`` and has *collided* when its last move was
refused (Stage's stall). Either ends its episode (terminated); the step limit truncates it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache, cached_property
from types import ModuleType

import numpy as np

from stage_sim.envs.scenarios import Scenario
from stage_sim.envs.spaces import ActionMap, ObservationBuilder, first_laser_ranges, goal_polar, layout_for
from stage_sim.sim.simulation import Simulation

#: Seeds handed to the simulation are drawn below this bound from the episode's generator.
SEED_BOUND = 2**63
#: Half the size of the cross that marks a goal in a frame, in metres.
GOAL_MARK = 0.15


@dataclass(frozen=True)
class RewardConfig:
    """Weights of the reward terms and the arrival radius (m)."""

    progress: float = 1.0
    arrival: float = 10.0
    collision: float = 10.0
    time: float = 0.01
    goal_tolerance: float = 0.3

    @cached_property
    def weights(self) -> np.ndarray:
        """The terms' weights and the tolerance as the compiled score takes them (read-only), made once."""
        weights = np.array([self.progress, self.arrival, self.collision, self.time, self.goal_tolerance])
        weights.flags.writeable = False
        return weights


@dataclass(frozen=True)
class StepOutcome:
    """Per agent: reward, arrived, collided (all (A,) arrays)."""

    reward: np.ndarray
    arrived: np.ndarray
    collided: np.ndarray


def score(config: RewardConfig, before: np.ndarray, after: np.ndarray, stalled: np.ndarray) -> StepOutcome:
    """Rewards for one step from the goal distances before and after it and the stall flags."""
    arrived = after <= config.goal_tolerance
    collided = stalled & ~arrived
    reward = (config.progress * (before - after) + config.arrival * arrived - config.collision * collided
              - config.time)
    return StepOutcome(reward.astype(np.float64), arrived, collided)


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
    """Per agent (A,) arrays of one step; ``active`` tells which agents were still in the episode. The arrays
    other than the observations may be the task's own, written again by its next step."""

    observations: np.ndarray
    rewards: np.ndarray
    terminated: np.ndarray
    truncated: np.ndarray
    arrived: np.ndarray
    collided: np.ndarray
    distance: np.ndarray
    active: np.ndarray


def body_commands(commands: np.ndarray) -> np.ndarray:
    """(A, 3) body commands (v, 0, ω) for the simulation from (A, 2) commands (v, ω)."""
    out = np.zeros((len(commands), 3))
    out[:, 0], out[:, 2] = commands[:, 0], commands[:, 1]
    return out


def command_agents(sim: Simulation, agents: np.ndarray, action_map: ActionMap, actions: np.ndarray,
                   active: np.ndarray) -> None:
    """Command robot ``agents[a]`` of ``sim`` with agent a's action, zero for agents whose episode ended (the
    numpy reference of :func:`compiled_command_agents`)."""
    sim.set_velocities(agents, body_commands(action_map.commands(actions) * active[:, None]))


def step_result(
    outcome: StepOutcome, observations: np.ndarray, distance: np.ndarray, active: np.ndarray, at_limit: np.ndarray,
) -> StepResult:
    """The step's result: an agent's episode ends by arriving or colliding (terminated), else at the step
    limit (truncated); inactive agents get nothing."""
    terminated = (outcome.arrived | outcome.collided) & active
    truncated = ~terminated & active & at_limit
    return StepResult(observations, outcome.reward * active, terminated, truncated,
                      outcome.arrived & active, outcome.collided & active, distance, active)


def finish_step(
    observer: ObservationBuilder, reward: RewardConfig, sim: Simulation, agents: np.ndarray, goals: np.ndarray,
    before: np.ndarray, active: np.ndarray, at_limit: bool,
) -> StepResult:
    """The step's result once ``sim`` has moved: observations, rewards from the goal distances ``before`` (A,)
    and those from the agents' new poses to ``goals`` (A, 2), episode ends; agents whose episode ends leave
    ``active`` (in place). The numpy reference of :func:`compiled_finish_step`."""
    distance, bearing = goal_polar(sim.true_poses[agents], goals)
    observations = observer.observe(sim, distance, bearing)
    outcome = score(reward, before, distance, sim.stalled[agents])
    result = step_result(outcome, observations, distance, active.copy(), at_limit)
    active &= ~(result.terminated | result.truncated)
    return result


@cache
def _kernels() -> ModuleType:
    """:mod:`stage_sim.envs.step_kernels`, imported on first use (it imports numba), as the simulation's
    compiled kernels are."""
    from stage_sim.envs import step_kernels

    return step_kernels


def compiled_command_agents(sim: Simulation, agents: np.ndarray, action_map: ActionMap, actions: np.ndarray,
                            active: np.ndarray) -> None:
    """:func:`command_agents` in one compiled pass (:mod:`stage_sim.envs.step_kernels`), which writes the rows
    of ``sim.commands`` and ``sim.last_command_us`` that :meth:`~stage_sim.sim.simulation.Simulation.set_velocities`
    writes."""
    kernels = _kernels()
    if action_map.discrete:
        kernels.discrete_commands(action_map.table, action_map.arrays(actions), active, agents,
                                  sim.commands, sim.last_command_us, sim.sim_time_us)
    else:
        kernels.continuous_commands(action_map.arrays(actions), action_map.low,
                                    action_map.high, active, agents, sim.commands, sim.last_command_us,
                                    sim.sim_time_us)


def compiled_finish_step(
    observer: ObservationBuilder, reward: RewardConfig, sim: Simulation, agents: np.ndarray, goals: np.ndarray,
    before: np.ndarray, active: np.ndarray, at_limit: bool,
) -> StepResult:
    """:func:`finish_step` in one compiled pass: goal distance and bearing, observe, score and end episodes."""
    rows, rewards, distance, flags = _kernels().observe_and_score(
        first_laser_ranges(sim, agents), observer.range_scale, observer.history, sim.true_poses, sim.velocities,
        sim.stalled, agents, goals, observer.tail_low, observer.tail_high, before, active,
        np.full(len(agents), at_limit), reward.weights)
    return StepResult(rows, rewards, flags[0], flags[1], flags[2], flags[3], distance, flags[4])


def compiled_finish_rows(
    observer: ObservationBuilder, reward: RewardConfig, ranges: np.ndarray, poses: np.ndarray,
    velocities: np.ndarray, stalled: np.ndarray, goals: np.ndarray, before: np.ndarray, active: np.ndarray,
    at_limit: np.ndarray,
) -> StepResult:
    """:func:`compiled_finish_step` of agents given as rows, agent a's newest ranges ``ranges[a]`` (A, B), pose,
    velocity and stall flag ``poses[a]``, ``velocities[a]``, ``stalled[a]``, at its step limit when
    ``at_limit[a]``: a vector env's worlds, one agent each, whose state the batch stepping them holds stacked (one
    compiled pass for all of them instead of a dozen numpy calls). Agents whose episode ends leave ``active``."""
    rows = np.arange(len(poses))
    contiguous = np.ascontiguousarray  # the arrays the warmed-up kernel takes, whatever robot a world's agent is
    observations, rewards, distance, flags = _kernels().observe_and_score(
        contiguous(ranges), observer.range_scale, observer.history, contiguous(poses), contiguous(velocities),
        contiguous(stalled), rows, goals, observer.tail_low, observer.tail_high, before, active, at_limit,
        reward.weights)
    return StepResult(observations, rewards, flags[0], flags[1], flags[2], flags[3], distance, flags[4])


class _CompiledStep:
    """A task's whole step in one compiled call (:mod:`stage_sim.envs.step_kernels`' ``continuous_step`` or
    ``discrete_step``, through :meth:`~stage_sim.sim.simulation.Simulation.step_with`): the tables it reads and
    writes, and the step results' arrays, which are they or views of them (made once)."""

    def __init__(self, task: NavigationTask) -> None:
        kernels = _kernels()
        observer, actions, count = task._observer, task.actions, len(task.agents)
        self.kernel = kernels.discrete_step if actions.discrete else kernels.continuous_step
        self.rewards, self.distance, flags = np.zeros(count), np.zeros(count), np.zeros((5, count), dtype=bool)
        self.flags = tuple(flags)  # terminated, truncated, arrived, collided, was active
        self.limits = (np.zeros(count, dtype=bool), np.ones(count, dtype=bool))  # every agent at its limit or none
        self.tables = kernels.task_tables(
            task._agent_rows, np.array([task.sim.beams_of(agent).start for agent in task.agents], dtype=np.int64),
            observer.range_scale, observer.history, observer.tail_low, observer.tail_high,
            task.config.reward.weights, actions.low, actions.high, actions.table, task.active, self.distance,
            self.rewards, flags)
        self.size = observer.layout.size


class NavigationTask:
    """Episodes of ``scenario`` for the robots ``agents`` (default: every robot of the world)."""

    def __init__(self, scenario: Scenario, config: TaskConfig, agents: list[int] | None = None) -> None:
        self.scenario = scenario
        self.config = config
        # The base of worlds made per episode is shared with the scenario's other tasks; a fixed world is stepped,
        # each task its own, made from that base (all that is static shared).
        base = scenario.simulation
        self._base = base if scenario.changes_world else base.with_static_models(scenario.base)
        self.sim = self._base
        self.agents = list(range(len(self._base.robots))) if agents is None else list(agents)
        self._agent_rows = np.asarray(self.agents, dtype=np.int64)
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
        scenario.check_room(self._base, self.agents)
        self._compiled: _CompiledStep | None = None  # made at the first step on the compiled kernels

    def reset(self, rng: np.random.Generator) -> np.ndarray:
        """A new episode drawn from ``rng``; returns the (A, D) first observations."""
        if self.scenario.changes_world:
            world = self.scenario.world(rng, self._base)
            self.sim = self._base.with_static_models(world, int(rng.integers(SEED_BOUND)))
        else:
            self.sim.reset(int(rng.integers(SEED_BOUND)))
        starts, self.goals = self.scenario.place(self.sim, self.agents, rng)
        for agent, start in zip(self.agents, starts, strict=True):
            self.sim.set_pose(agent, *start)
        # set_pose defers the lasers to the next step: one still step scans from the placed poses.
        self.sim.step()
        self._observer.reset(self.sim)
        self.active[:] = True
        self.steps = 0
        distance, bearing = goal_polar(self.sim.true_poses[self.agents], self.goals)
        self.distance[:] = distance  # in place: the compiled step's tables hold it
        return self._observer.rows(self.sim, self.distance, bearing)

    def step(self, actions: np.ndarray) -> StepResult:
        """Apply one action per agent (those of finished agents are ignored) and advance one step: in one compiled
        call when the simulation's step is one (:meth:`~stage_sim.sim.simulation.Simulation.step_with`), else
        command, step and score one after the other (the same arrays)."""
        sim, agents = self.sim, self._agent_rows
        compiled = sim.kernels == "numba"
        self.steps += 1
        at_limit = self.steps >= self.config.max_steps
        if compiled and sim.fused_next():
            whole = self._compiled or self._compile()
            rows = np.empty((len(agents), whole.size), dtype=np.float32)
            if sim.step_with(whole.kernel, (whole.tables, self.actions.arrays(actions), sim.last_command_us,
                                            sim.sim_time_us, self.goals, whole.limits[at_limit], rows)):
                return StepResult(rows, whole.rewards, *whole.flags[:4], self.distance, whole.flags[4])
        else:
            (compiled_command_agents if compiled else command_agents)(sim, agents, self.actions, actions, self.active)
            sim.step()
        result = (compiled_finish_step if compiled else finish_step)(
            self._observer, self.config.reward, sim, agents, self.goals, self.distance, self.active, at_limit)
        self.distance[:] = result.distance
        return result

    def _compile(self) -> _CompiledStep:
        """The tables of its compiled step, made once (its distances become the task's)."""
        self._compiled = _CompiledStep(self)
        self._compiled.distance[:] = self.distance
        self.distance = self._compiled.distance
        return self._compiled

    def frame(self) -> np.ndarray:
        """The world as the renderer draws it, (H, W, 3) uint8, with a cross in its robot's colour at each goal."""
        from PIL import Image, ImageDraw

        from stage_sim.rendering import palette, render, renderer_for

        picture = Image.fromarray(render(self.sim))
        view = renderer_for(self.sim).view()
        draw = ImageDraw.Draw(picture)
        width = max(1, round(view.scale * 0.03))
        for agent, goal in zip(self.agents, self.goals, strict=True):
            ink = palette.blend(self.sim.robots[agent].model.color)
            for diagonal in (np.array([1.0, 1.0]), np.array([1.0, -1.0])):
                ends = np.array([goal - GOAL_MARK * diagonal, goal + GOAL_MARK * diagonal])
                draw.line(view.continuous(ends).ravel().tolist(), fill=ink, width=width)
        return np.asarray(picture)
