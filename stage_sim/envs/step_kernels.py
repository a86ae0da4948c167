"""Compiled (numba) twin of a task step's arithmetic: the commands from the actions, written into the
simulation's command rows, then the goals' distance and bearing, the observations, rewards and episode ends
from the simulation's new state, each in one pass over the agents. A task's whole step is one call
(:func:`continuous_step`, :func:`discrete_step`: the commands, the simulation's step, the observations; through
:meth:`~stage_sim.sim.simulation.Simulation.step_with`); a step the simulation does not make in one call runs
the parts apart (:func:`stage_sim.envs.task.compiled_command_agents`, ``Simulation.step``,
:func:`stage_sim.envs.task.compiled_finish_step`).

Why: with one robot an env step is dominated by the dozens of small numpy calls of the reference
(:func:`stage_sim.envs.task.command_agents` and :func:`stage_sim.envs.task.finish_step`), not by
arithmetic; and then by the calls themselves (each compiled call checks the type of every argument, each
array it returns costs its caller some 0.7 µs to receive), which one call per step leaves one of.

Everything here is the reference's arithmetic operation for operation, in the same dtypes (float32 scans,
float64 rewards), so both give the same arrays bit for bit (``tests/envs/test_step_kernels.py``), with one
exception: the goal's bearing comes from libm's ``atan2``, which differs from numpy's (SVML on AVX-512
CPUs) in the last bit of some float64 values. The bearing only reaches the agent as a float32, which rounds
that bit away (no value of 20 million random poses differed, measured), and the distance (``hypot``), from
which the rewards come, is the same bit for bit. Used when the simulation runs the numba kernels.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba.core import types
from numba.experimental import structref

from stage_sim.sim import fused_kernels

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(inline="always", **_JIT)
def _clip(value, low, high):
    """``np.clip`` of one value between scalar bounds (numpy's vector loop): NaN stays NaN and a value equal to a
    bound stays itself (−0.0 at a bound 0.0)."""
    if value < low:
        value = low
    if value > high:
        value = high
    return value


@numba.njit(inline="always", **_JIT)
def _clip_between(value, low, high):
    """``np.clip`` of one value between bounds given per element (numpy's generic loop, max then min): NaN stays
    NaN and a value equal to a bound becomes the bound (−0.0 at a bound 0.0 becomes 0.0)."""
    if np.isnan(value):
        return value
    value = value if value > low else low
    return value if value < high else high


@numba.njit(**_JIT)
def continuous_commands(actions, low, high, active, rows, out, stamps, now):
    """(v, 0, ω) per agent a into row ``rows[a]`` of ``out``, stamped ``now`` in ``stamps``: the actions (A, 2)
    clamped into [low, high] (A, 2), times 0 or 1 for ``active``."""
    for a in range(actions.shape[0]):
        live = 1.0 if active[a] else 0.0
        row = rows[a]
        out[row, 0] = _clip_between(actions[a, 0], low[a, 0], high[a, 0]) * live
        out[row, 1] = 0.0
        out[row, 2] = _clip_between(actions[a, 1], low[a, 1], high[a, 1]) * live
        stamps[row] = now


@numba.njit(**_JIT)
def discrete_commands(table, chosen, active, rows, out, stamps, now):
    """(v, 0, ω) per agent a into row ``rows[a]`` of ``out``, stamped ``now`` in ``stamps``: row ``chosen[a]`` of
    its table (A, K, 2), times 0 or 1 for ``active``."""
    for a in range(chosen.shape[0]):
        live = 1.0 if active[a] else 0.0
        row = rows[a]
        out[row, 0] = table[a, chosen[a], 0] * live
        out[row, 1] = 0.0
        out[row, 2] = table[a, chosen[a], 1] * live
        stamps[row] = now


@numba.njit(inline="always", **_JIT)
def _goal_polar(pose, goal):
    """:func:`~stage_sim.envs.spaces.goal_polar` of one pose (3,) and goal (2,): distance and bearing."""
    dx, dy = goal[0] - pose[0], goal[1] - pose[1]
    bearing = math.atan2(dy, dx) - pose[2]
    return math.hypot(dx, dy), math.atan2(math.sin(bearing), math.cos(bearing))


@numba.njit(inline="always", **_JIT)
def _observe_into(ranges, first_beam, range_max, history, poses, velocities, stalled, agents, goals, tail_low,
                  tail_high, before, active, at_limit, weights, rows, rewards, distance, flags):
    """:func:`observe_and_score` into the given arrays, agent a's newest scan ``ranges[first_beam[a]:][:B]``
    (``before`` may be ``distance``: each agent's is read before it is written), agent a at its step limit when
    ``at_limit[a]``."""
    count, depth, beams = history.shape
    scans = depth * beams
    progress, arrival, collision, time, tolerance = weights[0], weights[1], weights[2], weights[3], weights[4]
    tail = np.empty(4, dtype=np.float32)
    for a in range(count):
        previous = before[a]
        # Element loops over views, each value written to the history and the row at once, the loop's counter the
        # only index (no negative index to wrap: the loops vectorise). Slice assignments (numba's setitem, which
        # guards against overlap) made this pass 3 times as long: 1.3 µs an agent of 512 beams.
        kept = history[a]
        for k in range(depth - 1):
            older, newer, out = kept[k], kept[k + 1], rows[a, k * beams:(k + 1) * beams]
            for b in range(beams):
                value = newer[b]
                older[b] = value
                out[b] = value
        newest, out = kept[depth - 1], rows[a, (depth - 1) * beams:scans]
        scan = ranges[first_beam[a]:first_beam[a] + beams]
        for b in range(beams):
            value = _clip(scan[b] / range_max, np.float32(0.0), np.float32(1.0))
            newest[b] = value
            out[b] = value
        robot = agents[a]
        distance[a], bearing = _goal_polar(poses[robot], goals[a])
        tail[0], tail[1] = np.float32(distance[a]), np.float32(bearing)
        tail[2], tail[3] = np.float32(velocities[robot, 0]), np.float32(velocities[robot, 2])
        for t in range(4):
            rows[a, scans + t] = _clip_between(tail[t], tail_low[a, t], tail_high[a, t])
        arrived = distance[a] <= tolerance
        collided = stalled[robot] and not arrived
        reward = (progress * (previous - distance[a]) + arrival * (1.0 if arrived else 0.0)
                  - collision * (1.0 if collided else 0.0) - time)
        live = active[a]
        terminated = (arrived or collided) and live
        truncated = not terminated and live and at_limit[a]
        rewards[a] = reward * (1.0 if live else 0.0)
        flags[0, a], flags[1, a] = terminated, truncated
        flags[2, a], flags[3, a], flags[4, a] = arrived and live, collided and live, live
        active[a] = live and not (terminated or truncated)


@numba.njit(**_JIT)
def observe_and_score(ranges, range_max, history, poses, velocities, stalled, agents, goals, tail_low, tail_high,
                      before, active, at_limit, weights):
    """Per agent a: its goal's distance and bearing from its robot's pose, shift the newest scan ``ranges[a]`` /
    ``range_max`` (clipped to [0, 1]) into ``history`` (A, k, B), its observation row (the history, then
    distance, bearing, forward speed and turn rate clipped to the tail bounds), its reward and (terminated,
    truncated, arrived, collided, was active) flags, truncated at its step limit (``at_limit[a]``: a vector env's
    worlds reach theirs apart); agents whose episode ends leave ``active``. Returns the
    rows (A, D) float32, rewards (A,), distances (A,) and flags (5, A), made here (arrays made in the kernel
    cost less than arrays handed to it). ``weights``: progress, arrival, collision, time, goal tolerance."""
    count, depth, beams = history.shape
    rows = np.empty((count, depth * beams + 4), dtype=np.float32)
    rewards, distance = np.empty(count), np.empty(count)
    flags = np.empty((5, count), dtype=np.bool_)
    _observe_into(np.ascontiguousarray(ranges).reshape(-1), np.arange(count) * beams, range_max, history, poses,
                  velocities, stalled, agents, goals, tail_low, tail_high, before, active, at_limit, weights, rows,
                  rewards, distance, flags)
    return rows, rewards, distance, flags


@structref.register
class TaskTablesType(types.StructRef):
    """numba's type of a :class:`TaskTables`."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class TaskTables(structref.StructRefProxy):
    """What a task's compiled step reads and writes besides the simulation and the step's own arguments
    (:data:`TABLES`), as one argument: numba checks the type of every argument of every call."""


#: What a :class:`TaskTables` holds, in the order :func:`task_tables` takes it: the agents' robots and where their
#: first laser's beams start among every beam, the range the scans are divided by, the scan history, the tail's
#: bounds, the reward weights, the actions' bounds (continuous) and table (discrete); then what every step
#: writes: which agents are active, their goal distances, rewards and (terminated, truncated, arrived, collided,
#: was active) flags.
TABLES = ("agents", "first_beam", "range_max", "history", "tail_low", "tail_high", "weights", "low", "high", "table",
          "active", "distance", "rewards", "flags")

structref.define_proxy(TaskTables, TaskTablesType, list(TABLES))


@numba.njit(**_JIT)
def task_tables(agents, first_beam, range_max, history, tail_low, tail_high, weights, low, high, table, active,
                distance, rewards, flags):
    """A :class:`TaskTables` of the :data:`TABLES` (compiled and cached: the proxy's own constructor is not)."""
    return TaskTables(agents, first_beam, range_max, history, tail_low, tail_high, weights, low, high, table, active,
                      distance, rewards, flags)


@numba.njit(inline="always", **_JIT)
def _step_and_observe(world, commands, velocities, poses, layers, layer, estimates, errors, dt, uses_odom, stalled,
                      cast, integrated, end_trig, final_trig, odometry, final, stalled_out, published, intensity, task,
                      goals, at_limit, rows):
    """The simulation's step, then :func:`_observe_into` from its new state, unless the robot layer was too small
    for its cast (the caller casts again, then observes)."""
    tiles = fused_kernels.commanded_step(world, commands, velocities, poses, layers, layer, estimates, errors, dt,
                                         uses_odom, stalled, cast, integrated, end_trig, final_trig, odometry, final,
                                         stalled_out, published, intensity)
    if tiles <= world.capacity:
        _observe_into(published, task.first_beam, task.range_max, task.history, final, velocities, stalled_out,
                      task.agents, goals, task.tail_low, task.tail_high, task.distance, task.active, at_limit,
                      task.weights, rows, task.rewards, task.distance, task.flags)
    return tiles


@numba.njit(**_JIT)
def continuous_step(world, commands, velocities, poses, layers, layer, estimates, errors, dt, uses_odom, stalled,
                    cast, integrated, end_trig, final_trig, odometry, final, stalled_out, published, intensity, task,
                    actions, stamps, now, goals, at_limit, rows):
    """A task's whole step in one call (:meth:`~stage_sim.sim.simulation.Simulation.step_with`): the agents'
    commands from continuous ``actions`` (:func:`continuous_commands`, stamped ``now``), the simulation's step
    (:func:`~stage_sim.sim.fused_kernels.commanded_step`), then the observation ``rows``, rewards, distances,
    flags and active agents into ``task`` (:func:`observe_and_score`'s arithmetic). Returns the step's answer."""
    continuous_commands(actions, task.low, task.high, task.active, task.agents, commands, stamps, now)
    return _step_and_observe(world, commands, velocities, poses, layers, layer, estimates, errors, dt, uses_odom,
                             stalled, cast, integrated, end_trig, final_trig, odometry, final, stalled_out, published,
                             intensity, task, goals, at_limit, rows)


@numba.njit(**_JIT)
def discrete_step(world, commands, velocities, poses, layers, layer, estimates, errors, dt, uses_odom, stalled, cast,
                  integrated, end_trig, final_trig, odometry, final, stalled_out, published, intensity, task, chosen,
                  stamps, now, goals, at_limit, rows):
    """:func:`continuous_step` with discrete actions ``chosen`` (:func:`discrete_commands`)."""
    discrete_commands(task.table, chosen, task.active, task.agents, commands, stamps, now)
    return _step_and_observe(world, commands, velocities, poses, layers, layer, estimates, errors, dt, uses_odom,
                             stalled, cast, integrated, end_trig, final_trig, odometry, final, stalled_out, published,
                             intensity, task, goals, at_limit, rows)
