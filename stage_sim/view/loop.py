"""A paced, pausable step loop for a core-only simulation with a view (``stage_sim view``, tests, benchmarks).

It paces steps as ``stageros``' steady timer does (one step per ``interval_sim / speedup`` wall seconds,
``speedup <= 0`` as fast as possible) and implements the view's :class:`~stage_sim.view.live.Controls` with
the calls ``stageros`` makes: :meth:`Simulation.set_velocity` for a command (the simulation's watchdog still
stops a robot nobody commands) and :meth:`Simulation.reset_positions` between steps.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from stage_sim.sim.simulation import Simulation
    from stage_sim.view.live import LiveView

IDLE_S = 1.0 / 60.0
"""Longest wait between two services of the view while paused or waiting for the next step."""
MAX_LAG_S = 1.0
"""A loop further behind its schedule than this (a stalled machine) starts afresh rather than catch up."""


class PacedLoop:
    """Steps ``sim`` in real time × ``speedup``; ``before_step`` (a controller) runs before every step."""

    def __init__(self, sim: Simulation, speedup: float, before_step: Callable[[], None] | None = None) -> None:
        self.sim = sim
        self.speedup = speedup
        self.paused = False
        self.before_step = before_step
        self.steps = 0

    def drive(self, robot: int, vx: float, vy: float, va: float) -> None:
        self.sim.set_velocity(robot, vx, vy, va)

    def reset_positions(self) -> None:
        self.sim.reset_positions()

    def set_paused(self, paused: bool) -> None:
        self.paused = paused

    def set_speedup(self, speedup: float) -> None:
        self.speedup = speedup

    def run(self, stop: threading.Event, view: LiveView | None = None, duration: float | None = None) -> None:
        """Step until ``stop`` is set or ``duration`` sim seconds have passed, servicing ``view`` in between."""
        sim = self.sim
        due = time.monotonic()
        while not stop.is_set() and (duration is None or sim.sim_time < duration - 1e-9):
            if view is not None:
                view.service()
            now = time.monotonic()
            if self.paused:
                stop.wait(IDLE_S)
                due = now
                continue
            if self.speedup > 0:
                if due > now:
                    stop.wait(min(due - now, IDLE_S))
                    continue
                due = max(due, now - MAX_LAG_S) + sim.interval / self.speedup
            else:
                due = now
            if self.before_step is not None:
                self.before_step()
            sim.step()
            self.steps += 1
