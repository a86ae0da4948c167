"""Ctrl-C and SIGTERM during a run: a request to stop, seen between steps, never an exception mid-step."""

from __future__ import annotations

import os
import signal

import pytest

from stage_sim.runs.interrupts import sigterm_interrupts, stop_requests
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world


@pytest.mark.parametrize("number", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_during_a_step_only_asks_the_loop_to_stop(number: int) -> None:
    """A KeyboardInterrupt raised inside a step can land in a numba kernel's callback (reported as a
    SystemError, `stage_sim run` then died with a traceback) or inside a lock (the run hung at exit)."""
    sim = Simulation(load_world("multi_robots.world"), seed=1)
    steps = 0
    before = signal.getsignal(number)  # whatever the test process has (ignored under nohup, rclpy's, ...)
    with stop_requests() as stop:
        while not stop.is_set():
            sim.step()
            steps += 1
            if steps == 3:
                os.kill(os.getpid(), number)  # delivered at once, in the middle of what follows
        assert steps <= 4
    assert signal.getsignal(number) is before  # the handlers are restored


def test_sigterm_interrupts_raise_keyboard_interrupt_only_inside_the_block() -> None:
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(KeyboardInterrupt), sigterm_interrupts():
        os.kill(os.getpid(), signal.SIGTERM)
    assert signal.getsignal(signal.SIGTERM) is before
