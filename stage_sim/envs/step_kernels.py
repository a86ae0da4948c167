"""Compiled (numba) twin of a task step's arithmetic: the commands from the actions, written into the
simulation's command rows, then the goals' distance and bearing, the observations, rewards and episode ends
from the simulation's new state, each in one pass over the agents (called through
:func:`stage_sim.envs.task.compiled_command_agents` and :func:`stage_sim.envs.task.compiled_finish_step`).

Why: with one robot an env step is dominated by the dozens of small numpy calls of the reference
(:func:`stage_sim.envs.task.command_agents` and :func:`stage_sim.envs.task.finish_step`), not by
arithmetic. Everything here is the reference's arithmetic operation for operation, in the same dtypes (float32
scans, float64 rewards), so both give the same arrays bit for bit (``tests/envs/test_step_kernels.py``), with
one exception: the goal's bearing comes from libm's ``atan2``, which differs from numpy's (SVML on AVX-512
CPUs) in the last bit of some float64 values. The bearing only reaches the agent as a float32, which rounds
that bit away (no value of 20 million random poses differed, measured), and the distance (``hypot``), from
which the rewards come, is the same bit for bit. Used when the simulation runs the numba kernels.
"""

from __future__ import annotations

import math

import numba
import numpy as np

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


@numba.njit(**_JIT)
def observe_and_score(ranges, range_max, history, poses, velocities, stalled, agents, goals, tail_low, tail_high,
                      before, active, at_limit, weights):
    """Per agent a: its goal's distance and bearing from its robot's pose, shift the newest scan ``ranges[a]`` /
    ``range_max`` (clipped to [0, 1]) into ``history`` (A, k, B), its observation row (the history, then
    distance, bearing, forward speed and turn rate clipped to the tail bounds), its reward and (terminated,
    truncated, arrived, collided, was active) flags; agents whose episode ends leave ``active``. Returns the
    rows (A, D) float32, rewards (A,), distances (A,) and flags (5, A), made here (arrays made in the kernel
    cost less than arrays handed to it). ``weights``: progress, arrival, collision, time, goal tolerance."""
    count, depth, beams = history.shape
    scans = depth * beams
    rows = np.empty((count, scans + 4), dtype=np.float32)
    rewards, distance = np.empty(count), np.empty(count)
    flags = np.empty((5, count), dtype=np.bool_)
    progress, arrival, collision, time, tolerance = weights[0], weights[1], weights[2], weights[3], weights[4]
    tail = np.empty(4, dtype=np.float32)
    for a in range(count):
        for k in range(depth - 1):
            history[a, k, :] = history[a, k + 1, :]
        for b in range(beams):
            history[a, depth - 1, b] = _clip(ranges[a, b] / range_max, np.float32(0.0), np.float32(1.0))
        for k in range(depth):
            rows[a, k * beams:(k + 1) * beams] = history[a, k, :]
        robot = agents[a]
        distance[a], bearing = _goal_polar(poses[robot], goals[a])
        tail[0], tail[1] = np.float32(distance[a]), np.float32(bearing)
        tail[2], tail[3] = np.float32(velocities[robot, 0]), np.float32(velocities[robot, 2])
        for t in range(4):
            rows[a, scans + t] = _clip_between(tail[t], tail_low[a, t], tail_high[a, t])
        arrived = distance[a] <= tolerance
        collided = stalled[robot] and not arrived
        reward = (progress * (before[a] - distance[a]) + arrival * (1.0 if arrived else 0.0)
                  - collision * (1.0 if collided else 0.0) - time)
        live = active[a]
        terminated = (arrived or collided) and live
        truncated = not terminated and live and at_limit
        rewards[a] = reward * (1.0 if live else 0.0)
        flags[0, a], flags[1, a] = terminated, truncated
        flags[2, a], flags[3, a], flags[4, a] = arrived and live, collided and live, live
        active[a] = live and not (terminated or truncated)
    return rows, rewards, distance, flags
