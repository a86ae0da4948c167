"""Where a robot has been lately, for telling when it is going nowhere and for backing out the way it came.

The laser does not see behind the robot, so the only ground behind it known to be clear is the path it has
just driven forward: the trail, which a retreat retraces in reverse (pure pursuit). The last half second
tells dithering (turning to and fro, creeping back and forth) from slow progress; the last 12 s tell being
stuck (a dead end the body cannot turn round in).
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from stage_sim.wander.frames import compose

STUCK_WINDOW_S = 12.0  # no 0.5 m of progress within this long: stuck
TRAIL_STEP = 0.05  # m between the remembered positions of the path driven forward, which a retreat retraces
TRAIL_LENGTH = 1.5  # m of that path kept: enough to back out of a dead end the body cannot turn in
STILL_S = 0.5  # s of going nowhere: within STILL_MOVE m, turning to and fro by at most STILL_TURN rad in all
STILL_MOVE, STILL_TURN, STILL_NET = 0.05, 0.25, 0.05  # net turn below STILL_NET rad: dithering, not a slow turn
RETREAT_MIN = 0.3  # m a retreat backs up before it may end (where the body can turn round)
RETREAT_LOOK = 0.3  # m back along the trail of the point a retreat steers for


class MotionHistory:
    """The trail driven forward, the poses of the last STILL_S and of the last STUCK_WINDOW_S (odometry frame)."""

    def __init__(self) -> None:
        self._trail: deque[tuple[float, float]] = deque(maxlen=round(TRAIL_LENGTH / TRAIL_STEP) + 1)
        self._recent: deque[tuple[float, float, float, float]] = deque()  # (time, x, y, net turn) over STILL_S
        self._progress: list[tuple[float, float, float]] = []  # (time, x, y) about once a second
        self._retreat_from = (0.0, 0.0)

    def extend_trail(self, pose: tuple[float, float, float], forward: float) -> None:
        """Remember the path driven forward (every TRAIL_STEP); backing up along it uses it up."""
        trail = self._trail
        if forward > 0 and (not trail or math.hypot(pose[0] - trail[-1][0], pose[1] - trail[-1][1]) >= TRAIL_STEP):
            trail.append((pose[0], pose[1]))
        elif forward < 0:
            while trail and math.hypot(pose[0] - trail[-1][0], pose[1] - trail[-1][1]) < TRAIL_STEP:
                trail.pop()

    def stuck(self, time: float, pose: tuple[float, float, float]) -> bool:
        """True when the robot has not got 0.5 m away from where it was STUCK_WINDOW_S ago."""
        if not self._progress or time - self._progress[-1][0] >= 1.0:
            self._progress.append((time, pose[0], pose[1]))
        while len(self._progress) > 1 and time - self._progress[1][0] >= STUCK_WINDOW_S:
            self._progress.pop(0)
        old_time, x, y = self._progress[0]
        if time - old_time >= STUCK_WINDOW_S and math.hypot(pose[0] - x, pose[1] - y) < 0.5:
            self._progress = [(time, pose[0], pose[1])]
            return True
        return False

    def standing_still(self, time: float, pose: tuple[float, float, float], net_turn: float, retreating: bool) -> bool:
        """True when for STILL_S the robot has got nowhere: dithering between small turns or creeping to and
        fro (never while retreating); ``net_turn`` is the radians turned so far."""
        recent = self._recent
        recent.append((time, pose[0], pose[1], net_turn))
        while time - recent[0][0] > STILL_S + 1e-6:
            recent.popleft()
        if retreating or time - recent[0][0] < STILL_S - 1e-6:
            return False
        history = np.array(recent)
        moved = np.hypot(history[:, 1] - pose[0], history[:, 2] - pose[1]).max()
        turns = history[:, 3]
        still = moved < STILL_MOVE and np.ptp(turns) < STILL_TURN and abs(turns[-1] - turns[0]) < STILL_NET
        if still:
            recent.clear()
        return bool(still)

    def forget_recent(self) -> None:
        """Judge standing still afresh from now."""
        self._recent.clear()

    def start_retreat(self, pose: tuple[float, float, float]) -> None:
        """A retreat begins here: distances backed are measured from this pose."""
        self._recent.clear()
        self._retreat_from = (pose[0], pose[1])

    def backed(self, pose: tuple) -> float:
        """Metres from where the current retreat began."""
        return math.hypot(pose[0] - self._retreat_from[0], pose[1] - self._retreat_from[1])

    def retreat_turn(self, pose: tuple, speed: float, free_to_turn: bool, until_free: bool) -> float | None:
        """The turn rate that backs the robot along its trail at ``speed`` (< 0; pure pursuit in reverse);
        None when the retreat is over: RETREAT_MIN back (and, ``until_free``, ``free_to_turn`` round in place),
        or out of trail."""
        if self.backed(pose) >= RETREAT_MIN and (not until_free or free_to_turn):
            return None
        trail = np.array(self._trail).reshape(-1, 2)[::-1]  # newest first
        if not len(trail):
            return None
        local = compose(pose, trail, inverse=True)
        far = np.flatnonzero(np.hypot(local[:, 0], local[:, 1]) >= RETREAT_LOOK)
        x, y = local[far[0] if len(far) else -1]
        if x >= 0:  # the trail is not behind the robot: it cannot be retraced in reverse
            return None
        return speed * 2 * y / (x * x + y * y)

    def trail_length(self, pose: tuple[float, float, float]) -> float:
        """Metres of remembered path behind the robot at ``pose`` (the room a retreat has)."""
        if not self._trail:
            return 0.0
        path = np.array([pose[:2], *reversed(self._trail)])
        return float(np.hypot(*np.diff(path, axis=0).T).sum())
