"""Rounds of refusals: looking only near the robots a round moved back gives the refusals of looking at all.

After a round, a clash must involve a robot that round moved back (the others share the cells they had
then), so :class:`~stage_sim.sim.collision.CollisionChecker` narrows the next round's test to the robots
within touching distance of those. Here every round is run both ways on a jammed crowd.
"""

from __future__ import annotations

import numpy as np
import pytest

from stage_sim.sim import collision
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text

WORLD = """
resolution 0.02
interval_sim 100
define bot position ( size [0.4 0.3 0.2] drive "omni" )
model( size [12 12 0.5] pose [0 0 0 0] boundary 1 )
"""


def crowd(count: int, seed: int) -> str:
    """Robots on a 0.45 m lattice, turned at random: neighbours touch after a step or two of driving."""
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(count)))
    lines = [f"bot( pose [{-5 + 0.45 * (i % side):.3f} {-5 + 0.45 * (i // side):.3f} 0 {rng.uniform(-180, 180):.1f}] )"
             for i in range(count)]
    return WORLD + "\n".join(lines) + "\n"


def run(kernels: str, narrowing: int, monkeypatch: pytest.MonkeyPatch) -> tuple[list[bytes], int]:
    monkeypatch.setattr(collision, "NARROWING_PAIRS", narrowing)
    sim = Simulation(load_world_text(crowd(400, 3), "crowd.world"), seed=1, kernels=kernels)
    commands = np.random.default_rng(7).uniform([-0.5, -0.5, -2.0], [0.8, 0.5, 2.0], (12, len(sim.robots), 3))
    frames, stalls = [], 0
    for step_commands in commands:
        for i, command in enumerate(step_commands):
            sim.set_velocity(i, *command)
        sim.step()
        frames.append(sim.true_poses.tobytes() + sim.stalled.tobytes())
        stalls += int(sim.stalled.sum())
    return frames, stalls


@pytest.mark.parametrize("kernels", ["numpy", "numba"])
def test_narrowed_rounds_refuse_what_the_full_test_refuses(kernels: str, monkeypatch: pytest.MonkeyPatch) -> None:
    narrowed, stalls = run(kernels, collision.NARROWING_PAIRS, monkeypatch)
    full, _ = run(kernels, 0, monkeypatch)  # no narrowing: every round tests every colliding robot
    assert stalls > 100  # the crowd jams: rounds of refusals happen
    assert narrowed == full
