"""Compiled (numba) twin of a task step's arithmetic: the commands from the actions, then the observations,
rewards and episode ends from the simulation's new state, each in one pass over the agents (called through
:func:`stage_sim.envs.task.compiled_commands` and :func:`stage_sim.envs.task.compiled_finish_step`).

Why: with one robot an env step is dominated by the dozens of small numpy calls of the reference
(:func:`stage_sim.envs.task.reference_commands` and :func:`stage_sim.envs.task.finish_step`), not by
arithmetic. The goal's distance and bearing stay in numpy (:func:`~stage_sim.envs.spaces.goal_polar`: its
trigonometry differs from libm's in the last bit on some CPUs); everything here is the reference's arithmetic
operation for operation, in the same dtypes (float32 scans, float64 rewards), so both give the same arrays bit
for bit (``tests/envs/test_step_kernels.py``). Used when the simulation runs the numba kernels.
"""

from __future__ import annotations

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
def continuous_commands(actions, low, high, active, out):
    """(v, 0, ω) per agent: the actions (A, 2) clamped into [low, high] (A, 2), times 0 or 1 for ``active``."""
    for a in range(actions.shape[0]):
        live = 1.0 if active[a] else 0.0
        out[a, 0] = _clip_between(actions[a, 0], low[a, 0], high[a, 0]) * live
        out[a, 1] = 0.0
        out[a, 2] = _clip_between(actions[a, 1], low[a, 1], high[a, 1]) * live


@numba.njit(**_JIT)
def discrete_commands(table, chosen, active, out):
    """(v, 0, ω) per agent: row ``chosen[a]`` of its table (A, K, 2), times 0 or 1 for ``active``."""
    for a in range(chosen.shape[0]):
        live = 1.0 if active[a] else 0.0
        out[a, 0] = table[a, chosen[a], 0] * live
        out[a, 1] = 0.0
        out[a, 2] = table[a, chosen[a], 1] * live


@numba.njit(**_JIT)
def observe_and_score(ranges, range_max, history, velocities, stalled, agents, distance, bearing, tail_low, tail_high,
                      before, active, at_limit, weights, rows, rewards, flags):
    """Per agent a: shift the newest scan ``ranges[a]`` / ``range_max`` (clipped to [0, 1]) into ``history``
    (A, k, B), write its observation row into ``rows`` (the history, then distance, bearing, forward speed and
    turn rate clipped to the tail bounds), its reward into ``rewards`` and (terminated, truncated, arrived,
    collided) into ``flags`` (4, A); agents whose episode ends leave ``active``. ``weights``: progress,
    arrival, collision, time, goal tolerance."""
    count, depth, beams = history.shape
    scans = depth * beams
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
        tail[0], tail[1] = np.float32(distance[a]), np.float32(bearing[a])
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
        flags[2, a], flags[3, a] = arrived and live, collided and live
        active[a] = live and not (terminated or truncated)
