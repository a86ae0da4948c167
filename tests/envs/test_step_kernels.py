"""The compiled step arithmetic gives the numpy reference's arrays bit for bit, edge values included."""

from __future__ import annotations

import copy
import math
from types import SimpleNamespace

import numpy as np
import pytest

from stage_sim.envs.spaces import TAIL, ActionMap, ObservationBuilder, ObservationLayout
from stage_sim.envs.task import (
    RewardConfig,
    compiled_commands,
    compiled_finish_step,
    finish_step,
    reference_commands,
)

AGENTS = 5
BEAMS = 16
BOUNDS = np.array([[0.0, 1.0, 0, 0, 0, 0, -math.pi / 2, math.pi / 2]] * 4 + [[-0.5, 2.0, 0, 0, 0, 0, -1.0, 0.5]])


def same(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal bit for bit (NaN equals NaN, −0.0 differs from 0.0)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("discrete", [False, True])
def test_commands_match_the_reference(discrete: bool) -> None:
    rng = np.random.default_rng(0)
    action_map = ActionMap(BOUNDS, discrete)
    for _ in range(200):
        if discrete:
            actions = rng.integers(0, action_map.table.shape[1], AGENTS)
        else:
            actions = rng.uniform(-3, 3, (AGENTS, 2)).astype(rng.choice([np.float32, np.float64]))
            actions.flat[rng.integers(0, actions.size, 3)] = rng.choice([-0.0, 0.0, np.nan, 1.0, -1.0], 3)
        active = rng.random(AGENTS) < 0.7
        assert same(compiled_commands(action_map, actions, active), reference_commands(action_map, actions, active))


def test_observations_rewards_and_ends_match_the_reference() -> None:
    rng = np.random.default_rng(1)
    layout = ObservationLayout(3, BEAMS, 4.0, math.pi, 12.0)
    action_map = ActionMap(BOUNDS, False)
    spaces = [layout.space(b) for b in BOUNDS]
    agents = np.array([0, 2, 3, 5, 6])
    reference = ObservationBuilder(layout, list(agents), spaces)
    compiled = copy.deepcopy(reference)
    reward = RewardConfig(progress=1.3, arrival=7.0, collision=-2.5, time=0.01, goal_tolerance=0.4)
    before = rng.uniform(0, 3, AGENTS)
    active = np.ones(AGENTS, dtype=bool)
    for step in range(300):
        scans = [[SimpleNamespace(ranges=rng.choice(
            [rng.uniform(0, 5), 0.0, -0.0, 4.0, np.nan, 3.9999998], BEAMS).astype(np.float32))] for _ in range(7)]
        velocities = rng.choice([0.0, -0.0, 0.3, 5.0, -2.0, np.nan], (7, 3))
        sim = SimpleNamespace(scans=scans, velocities=velocities, stalled=rng.random(7) < 0.2)
        distance = rng.choice([rng.uniform(0, 3), 0.4, 0.0, 20.0], AGENTS)
        bearing = rng.uniform(-4, 4, AGENTS)
        if step % 50 == 0:
            active[:] = True
        mine_active, their_active = active.copy(), active.copy()
        at_limit = step % 7 == 0
        mine = compiled_finish_step(compiled, reward, sim, agents, distance, bearing, before, mine_active, at_limit)
        theirs = finish_step(reference, reward, sim, agents, distance, bearing, before, their_active, at_limit)
        for field in ("observations", "rewards", "terminated", "truncated", "arrived", "collided", "distance",
                      "active"):
            assert same(getattr(mine, field), getattr(theirs, field)), (step, field)
        assert same(mine_active, their_active) and same(compiled.history, reference.history)
        assert mine.observations.shape == (AGENTS, layout.size) and TAIL == 4
        active, before = mine_active, distance
    assert action_map.table.shape[1] == 15
