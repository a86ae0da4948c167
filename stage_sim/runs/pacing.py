"""When a running simulation takes its next step: the one schedule of ``stage_sim run``, ``stage_sim view``,
``stageros`` and the launch scripts.

A run steps at real time × ``speedup`` (the world's ``speedup`` unless the user gives one; ``<= 0``: as fast as
possible), may be paused, and ends at the earlier of the world's ``quit_time`` and ``--duration``. Whoever runs
the loop asks :meth:`Pacer.steps` which steps are due now and :meth:`Pacer.wait_s` how long to sleep before the
next; in between it services its other work (a view, ROS callbacks, Ctrl-C). The rule for kernel threads of
such a run (:func:`threads_for_run`) and the command watchdog every entry point sets (:data:`WATCHDOG_S`) live
here too, so that all of them agree.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

from stage_sim.backend import available_cores, resolve_threads

MAX_LAG_S = 1.0
"""A loop further behind its schedule than this (a stalled machine) starts afresh rather than catch up."""
FAST_BATCH_S = 0.002
"""Wall seconds of back-to-back steps with ``speedup <= 0`` before the loop's host gets a turn (at least one
step per turn). One ROS executor round costs about as much as a step of a small world, so commands, resets
and a view still get in hundreds of times a second."""
WATCHDOG_S = 0.2
"""Sim seconds a velocity command lasts without a new one: stageros' ``base_watchdog_timeout`` default, which
``stage_sim view`` and the sessions use too (``<= 0``: forever)."""
END_TOLERANCE_S = 1e-9
"""Sim times this close below the end count as the end (sim time is a sum of float intervals)."""


def run_speedup(requested: float | None, world_speedup: float) -> float:
    """The speedup of a run: the user's (``--speedup``, a parameter), else the world's ``speedup``."""
    return world_speedup if requested is None else requested


def run_end(quit_time: float, duration: float | None = None) -> float:
    """The sim time a run ends at: the earlier of the world's ``quit_time`` (``<= 0``: none) and ``duration``
    (None: none); infinity when neither is set (the run goes on until stopped)."""
    ends = [t for t in (quit_time if quit_time > 0 else None, duration) if t is not None]
    return min(ends, default=math.inf)


@dataclass
class Pacer:
    """The step schedule of one run: ``interval`` sim seconds per step at ``speedup`` × real time, paused or
    not, until ``sim_time()`` reaches ``end``. ``clock`` gives wall seconds (monotonic)."""

    interval: float
    speedup: float
    sim_time: Callable[[], float]
    end: float = math.inf
    clock: Callable[[], float] = time.monotonic
    paused: bool = False
    _due: float = field(init=False)

    def __post_init__(self) -> None:
        self._due = self.clock()

    @property
    def period(self) -> float:
        """Wall seconds per step (0: as fast as possible)."""
        return self.interval / self.speedup if self.speedup > 0 else 0.0

    def finished(self) -> bool:
        """The run has reached its end."""
        return self.sim_time() >= self.end - END_TOLERANCE_S

    def steps(self) -> Iterator[None]:
        """Yield once per step to take now (the caller steps, then resumes the iteration). Paced, one step
        if the schedule has reached it: a late loop catches up turn by turn (:meth:`wait_s` says 0), with its host's
        work (commands above all, which the watchdog counts in sim time) in between; a schedule more than
        MAX_LAG_S behind starts afresh from now. With ``speedup <= 0`` steps back to back for FAST_BATCH_S of
        wall time, at least one. Nothing while paused or finished."""
        started = self.clock()
        taken = 0
        while not (self.paused or self.finished()):
            now = self.clock()
            if self.speedup > 0:
                if taken:
                    return
                if now - self._due > MAX_LAG_S:
                    self._due = now
                if now < self._due:
                    return
                self._due += self.period
            elif taken and now - started >= FAST_BATCH_S:
                return
            taken += 1
            yield

    def wait_s(self) -> float:
        """Wall seconds until the next step is due: 0 now (and once finished: the caller's loop ends),
        infinity while paused."""
        if self.finished():
            return 0.0
        if self.paused:
            return math.inf
        return max(0.0, self._due - self.clock()) if self.speedup > 0 else 0.0

    def set_paused(self, paused: bool) -> None:
        """Stop or resume stepping; a resumed run is due a step at once and keeps no debt from the pause."""
        self.paused = paused
        self._due = self.clock()

    def set_speedup(self, speedup: float) -> None:
        """Step at a new real-time factor (``<= 0``: as fast as possible), on a schedule starting now."""
        self.speedup = speedup
        self._due = self.clock()


def let_idle_threads_sleep(realtime: bool, threads: int) -> None:
    """Before a run paced to the wall clock on more than one thread: make numba's OpenMP workers sleep
    between the step's parallel loops instead of spinning through the pause (libgomp's default, right for
    back-to-back steps: stageros with 100 robots at real time on 2 threads used 18 % of a core, 7 % without;
    6.6 % on one thread). Acts only if the thread pool has not started yet; a user's own
    ``OMP_WAIT_POLICY`` wins."""
    if realtime and threads > 1:
        os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")


def threads_for_run(requested: int | None, speedup: float, recording: bool = False) -> int:
    """Threads of a run at ``speedup`` (<= 0: as fast as possible): the argument, else ``$STAGE_SIM_THREADS``,
    else 1 when paced to the wall clock and all cores when not, but one when ``recording`` a bag: its writer
    process then has a core of its own (sharing one, it preempted a simulation thread at every parallel loop,
    and the other waited: 100 robots on 2 cores recorded at 3.06 s of wall time on 2 threads, 2.47 s on 1,
    best of 3 alternated). Idle workers of a paced run sleep (:func:`let_idle_threads_sleep`). What
    ``stageros``, ``stage_sim run``, ``stage_sim view`` and the launch scripts use."""
    unpaced = max(1, available_cores() - 1) if recording else 0  # 0: all cores
    default = 1 if speedup > 0 else unpaced
    threads = resolve_threads(requested, default=default)
    let_idle_threads_sleep(speedup > 0, threads)
    return threads
