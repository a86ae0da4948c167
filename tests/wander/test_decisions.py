"""The wanderer decides exactly as recorded: every command float of three closed-loop runs (see decisions.py)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.wander.decisions import FIXTURE, RUNS, run


@pytest.mark.parametrize(("world", "seed", "steps"), RUNS)
def test_commands_are_exactly_the_recorded_ones(world: str, seed: int, steps: int) -> None:
    recorded = np.load(FIXTURE)
    commands, digests = run(world, seed, steps)
    expected, expected_digests = recorded[f"{world}:commands"], recorded[f"{world}:digests"]
    assert commands.shape == expected.shape
    differs = np.flatnonzero(np.any(commands != expected, axis=(1, 2)))
    if len(differs):
        step = int(differs[0])
        inputs_changed = np.flatnonzero(np.any(digests[: step + 1] != expected_digests[: step + 1], axis=1))
        cause = (f"the simulation's scans or odometry changed first (step {inputs_changed[0]}), not the wanderer"
                 if len(inputs_changed) else "the wanderer decided differently on the same inputs")
        pytest.fail(f"{world} seed {seed}: step {step} commanded {commands[step].tolist()}, recorded "
                    f"{expected[step].tolist()}: {cause}")
