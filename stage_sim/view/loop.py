"""A paced, pausable step loop for a core-only simulation with a view (``stage_sim view``, tests, benchmarks).

It steps on the schedule every entry point shares (:class:`~stage_sim.runs.pacing.Pacer`: real time ×
``speedup``, ``speedup <= 0`` as fast as possible, the lag cap, the run's end) and implements the view's
:class:`~stage_sim.view.live.Controls` with the calls ``stageros`` makes: :meth:`Simulation.set_velocity` for
a command (the simulation's watchdog still stops a robot nobody commands) and
:meth:`Simulation.reset_positions` between steps.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING

from stage_sim.runs.pacing import Pacer

if TYPE_CHECKING:
    from stage_sim.sim.simulation import Simulation
    from stage_sim.view.live import LiveView

IDLE_S = 1.0 / 60.0
"""Longest wait between two services of the view while paused or waiting for the next step."""


class PacedLoop:
    """Steps ``sim`` in real time × ``speedup`` until sim time ``end``; ``before_step`` (a controller) runs
    before every step."""

    def __init__(self, sim: Simulation, speedup: float, before_step: Callable[[], None] | None = None,
                 end: float = math.inf) -> None:
        self.sim = sim
        self.pacer = Pacer(sim.interval, speedup, lambda: sim.sim_time, end)
        self.before_step = before_step

    def drive(self, robot: int, vx: float, vy: float, va: float) -> None:
        self.sim.set_velocity(robot, vx, vy, va)

    def reset_positions(self) -> None:
        self.sim.reset_positions()

    def set_paused(self, paused: bool) -> None:
        self.pacer.set_paused(paused)

    def set_speedup(self, speedup: float) -> None:
        self.pacer.set_speedup(speedup)

    def run(self, stop: threading.Event, view: LiveView | None = None) -> None:
        """Step until ``stop`` is set or the run's end, servicing ``view`` in between."""
        pacer = self.pacer
        while not (stop.is_set() or pacer.finished()):
            if view is not None:
                view.service()
            for _ in pacer.steps():
                if self.before_step is not None:
                    self.before_step()
                self.sim.step()
            stop.wait(min(pacer.wait_s(), IDLE_S))
