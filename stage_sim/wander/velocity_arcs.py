"""Constant-twist arcs for a planar robot and the wanderer's fixed set of candidate commands.

A command held for ``t`` seconds from the origin moves the body along a circular arc (a straight line when
the turn rate is zero); :func:`arc_poses` gives the exact poses so that a planner can check a whole command
set against obstacle points at once.
"""

from __future__ import annotations

import numpy as np

from stage_sim.wander.config import WanderConfig


def arc_poses(commands: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Exact poses (C, T, 3) reached from the origin holding each body twist (vx, vy, wz) for ``times``."""
    vx, vy, w = (commands[:, k, None] for k in range(3))
    yaw = w * times
    small = np.abs(w) < 1e-9
    safe_w = np.where(small, 1.0, w)
    sin_term = np.where(small, times, np.sin(yaw) / safe_w)
    cos_term = np.where(small, 0.0, (1 - np.cos(yaw)) / safe_w)
    return np.stack([vx * sin_term - vy * cos_term, vx * cos_term + vy * sin_term, yaw], axis=-1)


def candidate_commands(config: WanderConfig) -> np.ndarray:
    """The fixed command set (C, 3): forward arcs, turns in place, a slow reverse; never all zero."""
    turns = np.linspace(-config.turn_rate, config.turn_rate, 13)
    speeds = [-0.15, *np.linspace(0.0, config.forward_speed, 7)]
    commands = [(v, 0.0, w) for v in speeds for w in turns]
    if config.holonomic:
        side = min(0.3, config.forward_speed)
        commands += [(v, vy, w) for v in (0.0, side) for vy in (-side, side) for w in (-0.4, 0.0, 0.4)]
    array = np.array(commands)
    return array[np.any(array != 0.0, axis=1)]
