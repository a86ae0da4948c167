"""Reward and episode end for a goal-reaching robot, per agent per step, computed for all agents at once.

``reward = progress · (d_before − d_after) + arrival · [arrived] − collision · [collided] − time``
where d is the distance to the goal; an agent has *arrived* when d ≤ ``goal_tolerance`` and has
*collided* when its last move was refused (Stage's stall). Either ends its episode (terminated);
the step limit truncates it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RewardConfig:
    """Weights of the reward terms and the arrival radius (m)."""

    progress: float = 1.0
    arrival: float = 10.0
    collision: float = 10.0
    time: float = 0.01
    goal_tolerance: float = 0.3


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
