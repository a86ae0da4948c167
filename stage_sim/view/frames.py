"""Frames: the moving state of a simulation, sampled on its own thread and encoded once for every page.

A frame is taken only when one is due (at most :data:`MAX_FPS` per wall second) and something changed,
so a simulation running a thousand steps a second costs the view thirty small copies a second, and a
paused one none. Laser ranges travel as base64 float32 so that a 1,000-beam laser is 5 kB, not 20 kB of
decimal text.
"""

from __future__ import annotations

import base64
import json
from collections import deque
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from stage_sim.sim.simulation import Simulation

MAX_FPS = 30.0
SLACK = 0.2
"""Share of a frame period by which a caller on a timer of the frame rate may be early."""
RATE_WINDOW_S = 1.0
"""Wall seconds over which the real-time factor shown on the page is measured."""


class FrameSampler:
    """Decides when a frame is due and encodes it as the JSON text the page reads."""

    def __init__(self, sim: Simulation, max_fps: float = MAX_FPS) -> None:
        self.sim = sim
        self.period = 1.0 / max_fps
        self._next = 0.0
        self._last_key: tuple | None = None
        self._history: deque[tuple[float, float]] = deque()

    def due(self, now: float) -> bool:
        """True when the next frame period has begun (a timer firing a little early still counts)."""
        return now >= self._next - SLACK * self.period

    def take(self, now: float, paused: bool, speedup: float, force: bool = False) -> str | None:
        """The frame of the simulation now, or None when nothing changed since the last one (``force``:
        always); starts the next frame period either way."""
        sim = self.sim
        late = now - self._next >= self.period
        self._next = now + self.period if late else self._next + self.period
        rate = self._rate(now, sim.sim_time)
        key = (sim.sim_time_us, sim.true_poses.tobytes(), paused, speedup)
        if key == self._last_key and not force:
            return None
        self._last_key = key
        ranges = [
            [base64.b64encode(np.asarray(scan.ranges, dtype="<f4").tobytes()).decode("ascii") for scan in scans]
            for scans in sim.scans
        ]
        frame = {
            "type": "frame",
            "time": sim.sim_time,
            "rtf": None if paused else rate,
            "paused": paused,
            "speedup": speedup,
            "poses": np.round(sim.true_poses, 5).tolist(),
            "odometry": np.round(sim.odometry_poses, 5).tolist(),
            "velocities": np.round(sim.velocities, 4).tolist(),
            "true_velocities": np.round(sim.true_velocities, 4).tolist(),
            "stalled": sim.stalled.tolist(),
            "ranges": ranges,
        }
        return json.dumps(frame, separators=(",", ":"))

    def _rate(self, now: float, sim_time: float) -> float | None:
        """Sim seconds per wall second over the last :data:`RATE_WINDOW_S` (None until measurable)."""
        history = self._history
        if history and sim_time < history[-1][1]:
            history.clear()  # the simulation was reset
        history.append((now, sim_time))
        while len(history) > 2 and now - history[1][0] >= RATE_WINDOW_S:
            history.popleft()
        (t0, s0), (t1, s1) = history[0], history[-1]
        return (s1 - s0) / (t1 - t0) if t1 - t0 > 0.1 else None
