"""What an agent commands: a forward speed and a turn rate, continuous within its ``velocity_bounds`` or
chosen from a small table (the discrete variant).

The discrete table is every pair of a forward fraction in :data:`FORWARD` and a turn fraction in
:data:`TURN` of the bounds' upper limits, forward fractions first: action ``i`` is
``(FORWARD[i // len(TURN)] · v_max, TURN[i % len(TURN)] · ω_max)``, each clamped into the bounds.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

FORWARD = (0.0, 0.5, 1.0)
TURN = (-1.0, -0.5, 0.0, 0.5, 1.0)


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
        if self.discrete:
            chosen = np.asarray(actions, dtype=np.int64).reshape(-1)
            return self.table[np.arange(len(chosen)), chosen]
        return np.clip(np.asarray(actions, dtype=np.float64).reshape(-1, 2), self.low, self.high)

    def nearest(self, commands: np.ndarray) -> np.ndarray:
        """The discrete action closest to each agent's wanted (v, ω), for scripted policies."""
        scale = np.maximum(self.high - self.low, 1e-9)[:, None]
        gaps = np.linalg.norm((commands[:, None, :] - self.table) / scale, axis=-1)
        return np.argmin(gaps, axis=1)
