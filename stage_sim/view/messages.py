"""What a page may ask for, checked field by field before anything reaches the simulation.

Every message is one JSON object of at most :data:`MAX_MESSAGE_BYTES` with a known ``type``; numbers must
be real finite numbers (not booleans, not strings) within sane limits, robots must be known names, poses
must lie near the world. Anything else raises :class:`BadMessage`, whose text says what was wrong; the
server drops such a message with a rate-limited warning and closes a connection that keeps sending them.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass
from typing import Any

MAX_MESSAGE_BYTES = 4096
ABSURD_COMMAND = 1e3
"""Velocities beyond this (m/s, rad/s) are garbage, as on ``cmd_vel``."""
MAX_SPEEDUP = 1e3
POSE_MARGIN_M = 10.0
"""A dragged robot may be dropped this far outside the static world, no farther."""


class BadMessage(ValueError):
    """A page message that is not one of the :data:`ACTIONS`, or not well formed."""


@dataclass(frozen=True)
class Drive:
    """Keyboard driving: the same command a ``cmd_vel`` message gives."""

    robot: int
    vx: float
    vy: float
    va: float


@dataclass(frozen=True)
class Place:
    """A robot dragged (or turned) to a new true pose; no ``yaw`` keeps its heading."""

    robot: int
    x: float
    y: float
    yaw: float | None


@dataclass(frozen=True)
class Pause:
    paused: bool


@dataclass(frozen=True)
class Speed:
    """Real-time factor; ``<= 0`` is as fast as possible (``--speedup`` semantics)."""

    speedup: float


@dataclass(frozen=True)
class Reset:
    """``reset_positions``."""


Action = Drive | Place | Pause | Speed | Reset


class MessageReader:
    """Turns page text into actions for one world: its robot names and its extent."""

    def __init__(self, names: list[str], bounds: tuple[float, float, float, float]) -> None:
        self.index = {name: i for i, name in enumerate(names)}
        x0, y0, x1, y1 = bounds
        self.bounds = (x0 - POSE_MARGIN_M, y0 - POSE_MARGIN_M, x1 + POSE_MARGIN_M, y1 + POSE_MARGIN_M)

    def read(self, text: str | bytes) -> Action:
        """The action ``text`` asks for; raises :class:`BadMessage` otherwise."""
        if not isinstance(text, str):
            raise BadMessage("binary message (the page sends JSON text)")
        if len(text) > MAX_MESSAGE_BYTES:
            raise BadMessage(f"message of {len(text)} characters (at most {MAX_MESSAGE_BYTES})")
        try:
            data = json.loads(text)
        except (ValueError, RecursionError) as exc:  # broken text, or nesting deeper than Python recurses
            raise BadMessage(f"not JSON: {str(exc)[:80]}") from None
        if not isinstance(data, dict):
            raise BadMessage("not a JSON object")
        kind = data.get("type")
        if kind == "drive":
            robot = self._robot(data)
            vx, vy, va = (_number(data, key, ABSURD_COMMAND) for key in ("vx", "vy", "va"))
            return Drive(robot, vx, vy, va)
        if kind == "pose":
            robot = self._robot(data)
            x0, y0, x1, y1 = self.bounds
            x, y = _number(data, "x", max(abs(x0), abs(x1))), _number(data, "y", max(abs(y0), abs(y1)))
            if not (x0 <= x <= x1 and y0 <= y <= y1):
                raise BadMessage(f"pose ({x:g}, {y:g}) is far outside the world")
            return Place(robot, x, y, _number(data, "yaw", 100.0) if "yaw" in data else None)
        if kind == "pause":
            paused = data.get("paused")
            if not isinstance(paused, bool):
                raise BadMessage("'paused' must be true or false")
            return Pause(paused)
        if kind == "speed":
            return Speed(_number(data, "speedup", MAX_SPEEDUP))
        if kind == "reset":
            return Reset()
        raise BadMessage(f"unknown message type {str(kind)[:40]!r}")

    def _robot(self, data: dict[str, Any]) -> int:
        name = data.get("robot")
        if not isinstance(name, str) or name not in self.index:
            raise BadMessage(f"unknown robot {str(name)[:40]!r}")
        return self.index[name]


def _number(data: dict[str, Any], key: str, limit: float) -> float:
    value = data.get(key)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise BadMessage(f"'{key}' must be a number")
    value = float(value)
    if not (math.isfinite(value) and abs(value) <= limit):
        raise BadMessage(f"'{key}' = {value} is not finite or beyond {limit:g}")
    return value


class Strikes:
    """Counts a connection's bad messages; too many in a window means it is closed."""

    def __init__(self, limit: int = 20, window_s: float = 5.0) -> None:
        self.limit, self.window_s = limit, window_s
        self._times: list[float] = []

    def add(self, now: float | None = None) -> bool:
        """Record one bad message; True when the connection has now sent too many."""
        now = time.monotonic() if now is None else now
        self._times = [t for t in self._times if now - t < self.window_s]
        self._times.append(now)
        return len(self._times) > self.limit
