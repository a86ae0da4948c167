"""What an agent observes and what it commands: the observation layout and the action map.

Observation: one flat float32 vector per agent (``D = k·B + 4`` for B beams)::

    [0, k·B)     the last k scans of its first laser, oldest first, each range / range_max in [0, 1]
    k·B          distance to the goal (m)
    k·B + 1      bearing of the goal in the robot frame (rad, counter-clockwise from ahead, in [-π, π])
    k·B + 2      forward speed (m/s) the robot moved at in the last step (0 while stalled)
    k·B + 3      turn rate (rad/s) of the last step

Action: a forward speed and a turn rate, continuous within the robot's ``velocity_bounds``, or (the
discrete variant) one pair of a forward fraction in :data:`FORWARD` and a turn fraction in :data:`TURN` of
the bounds' upper limits, forward fractions first: action ``i`` is
``(FORWARD[i // len(TURN)] · v_max, TURN[i % len(TURN)] · ω_max)``, clamped into the bounds.

Both are computed in one batch over all agents (no per-agent Python loop).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from stage_sim.sim.robots import RobotSpec
from stage_sim.sim.simulation import Simulation

#: Entries after the scans: goal distance, goal bearing, forward speed, turn rate.
TAIL = 4
#: Fractions of the upper velocity bounds that make the discrete actions.
FORWARD = (0.0, 0.5, 1.0)
TURN = (-1.0, -0.5, 0.0, 0.5, 1.0)


@dataclass(frozen=True)
class ObservationLayout:
    """Shape and meaning of an observation, so that a policy can read one (see the module docstring)."""

    history: int
    beams: int
    range_max: float
    fov: float
    max_distance: float

    @property
    def size(self) -> int:
        """Length of one observation vector."""
        return self.history * self.beams + TAIL

    @property
    def beam_angles(self) -> np.ndarray:
        """Direction of every beam in the robot frame (rad, counter-clockwise from −fov/2)."""
        if self.beams == 1:
            return np.zeros(1)
        return -self.fov / 2 + np.arange(self.beams) * (self.fov / (self.beams - 1))

    def latest_scan(self, observations: np.ndarray) -> np.ndarray:
        """The newest scan (normalised ranges) of each observation row (..., D) → (..., B)."""
        end = self.history * self.beams
        return observations[..., end - self.beams:end]

    def goal(self, observations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Goal (distance, bearing) of each observation row."""
        end = self.history * self.beams
        return observations[..., end], observations[..., end + 1]

    def space(self, bounds: np.ndarray) -> spaces.Box:
        """The observation space for a robot with ``velocity_bounds`` ``bounds`` (8,)."""
        scans = self.history * self.beams
        low = np.concatenate([np.zeros(scans), [0.0, -np.pi, bounds[0], bounds[6]]]).astype(np.float32)
        high = np.concatenate([np.ones(scans), [self.max_distance, np.pi, bounds[1], bounds[7]]]).astype(np.float32)
        return spaces.Box(low, high, dtype=np.float32)


def layout_for(sim: Simulation, agents: list[int], history: int) -> ObservationLayout:
    """The one layout every agent of ``sim`` shares; a clear error when their lasers differ or are missing."""
    lasers = {(r.rangers[0].sensor.samples, r.rangers[0].sensor.range_max, r.rangers[0].sensor.fov)
              for r in _agents(sim, agents)}
    if len(lasers) != 1:
        raise ValueError(f"the agents' first lasers differ (samples, range, fov: {sorted(lasers)}): "
                         "one observation layout needs one kind of laser")
    samples, range_max, fov = lasers.pop()
    height, width = sim.static.shape
    diagonal = float(np.hypot(height, width) * sim.static.resolution)
    return ObservationLayout(history, samples, range_max, fov, diagonal)


class ObservationBuilder:
    """Keeps every agent's scan history and writes observation rows straight into one float32 array."""

    def __init__(self, layout: ObservationLayout, agents: list[int], agent_spaces: list[spaces.Box]) -> None:
        self.layout = layout
        self.agents = np.asarray(agents, dtype=np.int64)
        self.range_scale = np.float32(layout.range_max)
        """The lasers' range as the compiled observation divides by it."""
        # A goal beyond the world's diagonal cannot happen; clipping the tail to the spaces is a guard.
        self.tail_low = np.array([space.low[-TAIL:] for space in agent_spaces], dtype=np.float32)
        self.tail_high = np.array([space.high[-TAIL:] for space in agent_spaces], dtype=np.float32)
        self.history = np.zeros((len(agents), layout.history, layout.beams), dtype=np.float32)
        """(A, k, B) normalised scans, oldest first (the compiled step, :mod:`stage_sim.envs.step_kernels`,
        shifts them too)."""

    def reset(self, sim: Simulation) -> None:
        """Fill every agent's history with its current scan (no older scan exists yet)."""
        self._normalise(self._ranges(sim), self.history[:, -1])
        self.history[:, :-1] = self.history[:, -1:]

    def observe(self, sim: Simulation, distance: np.ndarray, bearing: np.ndarray) -> np.ndarray:
        """Shift in the current scans and return (A, D) observations (goal distance and bearing given)."""
        return self.observe_arrays(self._ranges(sim), sim.velocities[self.agents], distance, bearing)

    def observe_arrays(
        self, ranges: np.ndarray, velocity: np.ndarray, distance: np.ndarray, bearing: np.ndarray,
    ) -> np.ndarray:
        """:meth:`observe` from the agents' newest ranges (A, B) and velocities (A, 3), wherever they come
        from (one simulation, or one per world in the vector env)."""
        self.history[:, :-1] = self.history[:, 1:]
        self._normalise(ranges, self.history[:, -1])
        return self._rows(velocity, distance, bearing)

    def restore(self, row: int, observation: np.ndarray) -> None:
        """Take row ``row``'s scan history from an observation (the first one of a world reset elsewhere)."""
        scans = self.layout.history * self.layout.beams
        self.history[row] = observation[:scans].reshape(self.layout.history, self.layout.beams)

    def rows(self, sim: Simulation, distance: np.ndarray, bearing: np.ndarray) -> np.ndarray:
        """(A, D) observations from the kept history, the goals' distance and bearing and the velocities."""
        return self._rows(sim.velocities[self.agents], distance, bearing)

    def _rows(self, velocity: np.ndarray, distance: np.ndarray, bearing: np.ndarray) -> np.ndarray:
        count, scans = len(self.agents), self.layout.history * self.layout.beams
        rows = np.empty((count, scans + TAIL), dtype=np.float32)
        rows[:, :scans] = self.history.reshape(count, scans)
        tail = rows[:, scans:]
        tail[:, 0], tail[:, 1], tail[:, 2], tail[:, 3] = distance, bearing, velocity[:, 0], velocity[:, 2]
        np.clip(tail, self.tail_low, self.tail_high, out=tail)
        return rows

    def _ranges(self, sim: Simulation) -> np.ndarray:
        return first_laser_ranges(sim, self.agents)

    def _normalise(self, ranges: np.ndarray, out: np.ndarray) -> None:
        """Ranges divided by the range and clipped to [0, 1], into ``out`` (A, B)."""
        np.divide(ranges, self.layout.range_max, out=out)
        np.clip(out, 0.0, 1.0, out=out)


def first_laser_ranges(sim: Simulation, robots: np.ndarray) -> np.ndarray:
    """(A, B) float32: the newest ranges of each robot's first laser. When the last cast measured every ranger,
    straight out of its beams (the scans are views of them), so that a step of an env makes no scan objects
    (about 2 µs a step for one robot); else from the latest scans. Read-only when it is a view."""
    measured = sim.measured_beams
    if measured is None or measured.due is not None:
        return np.stack([sim.scans[robot][0].ranges for robot in robots])
    if len(robots) == 1:
        return measured.ranges[sim.beams_of(int(robots[0]))][None]
    return np.stack([measured.ranges[sim.beams_of(int(robot))] for robot in robots])


def goal_polar(poses: np.ndarray, goals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance and robot-frame bearing (wrapped to [-π, π]) of each goal from each pose."""
    delta = goals - poses[:, :2]
    distance = np.hypot(delta[:, 0], delta[:, 1])
    bearing = np.arctan2(delta[:, 1], delta[:, 0]) - poses[:, 2]
    return distance, np.arctan2(np.sin(bearing), np.cos(bearing))


def _agents(sim: Simulation, agents: list[int]) -> list[RobotSpec]:
    robots = [sim.robots[i] for i in agents]
    bare = [r.name for r in robots if not r.rangers or not r.rangers[0].sensor.samples]
    if bare:
        raise ValueError(f"robots without a laser cannot be agents: {', '.join(bare)}")
    return robots


class ActionMap:
    """Turns the actions of A agents (each with its robot's ``velocity_bounds``, (A, 8)) into (v, ω), batched."""

    def __init__(self, bounds: np.ndarray, discrete: bool) -> None:
        self.discrete = discrete
        self.low = np.asarray(bounds, dtype=np.float64)[:, [0, 6]]
        self.high = np.asarray(bounds, dtype=np.float64)[:, [1, 7]]
        fractions = np.array([(f, t) for f in FORWARD for t in TURN])
        self.table = np.clip(fractions[None] * self.high[:, None], self.low[:, None], self.high[:, None])

    def space(self, agent: int) -> spaces.Space:
        """``Box([v_min, ω_min], [v_max, ω_max])`` or ``Discrete(len(FORWARD) · len(TURN))`` for agent ``agent``."""
        if self.discrete:
            return spaces.Discrete(self.table.shape[1])
        return spaces.Box(self.low[agent].astype(np.float32), self.high[agent].astype(np.float32), dtype=np.float32)

    def commands(self, actions: np.ndarray) -> np.ndarray:
        """(A, 2) commands (v, ω) from one action per agent; continuous ones are clamped into the bounds."""
        chosen = self.arrays(actions)
        if self.discrete:
            return self.table[np.arange(len(chosen)), chosen]
        return np.clip(chosen, self.low, self.high)

    def arrays(self, actions: np.ndarray) -> np.ndarray:
        """One action per agent as an array: (A,) int64 table rows, or (A, 2) float64 (v, ω) not yet clamped."""
        if self.discrete:
            return np.asarray(actions, dtype=np.int64).reshape(-1)
        return np.asarray(actions, dtype=np.float64).reshape(-1, 2)

    def nearest(self, commands: np.ndarray) -> np.ndarray:
        """The discrete action closest to each agent's wanted (v, ω), for scripted policies."""
        scale = np.maximum(self.high - self.low, 1e-9)[:, None]
        gaps = np.linalg.norm((commands[:, None, :] - self.table) / scale, axis=-1)
        return np.argmin(gaps, axis=1)
