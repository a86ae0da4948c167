"""A scripted baseline: head for the goal through the nearest gap the laser shows wide enough for the body.

It reads only the observation (newest scan, goal distance and bearing), so it runs through either
environment and shows what a learned policy has to beat. Per agent, in one batch:

1. Widen every obstacle by the body: a direction is open when no beam within the angle the body's
   half-width (plus ``margin``) subtends at that beam's range is shorter than ``lookahead`` (or than the goal,
   if nearer).
2. Aim at the open direction closest to the goal's bearing, shifted by ``right_bias`` towards the right
   (robots meeting head on then pass each other on the same side); a goal behind the laser's field of
   view is turned to in place.
3. Turn at ``gain`` · aim; drive at full speed scaled down by how far the aim is off ahead, how close the
   nearest beam ahead is (``slow_range``), and how near the goal is. With no open direction, turn in place
   towards the side with more room.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stage_sim.envs.spaces import ObservationLayout

#: The scan is pooled (nearest range) into this many sectors before the gaps are searched.
SECTORS = 90


@dataclass(frozen=True)
class GoalSeeker:
    """The reactive goal-seeking rule; call it with (A, D) observations to get (A, 2) commands (v, ω)."""

    layout: ObservationLayout
    max_speed: float
    max_turn: float
    radius: float = 0.2
    margin: float = 0.15
    lookahead: float = 1.5
    slow_range: float = 1.0
    right_bias: float = 0.25
    gain: float = 2.0

    def __call__(self, observations: np.ndarray) -> np.ndarray:
        observations = np.atleast_2d(observations)
        scan = self.layout.latest_scan(observations).astype(np.float64) * self.layout.range_max
        distance, bearing = (a.astype(np.float64) for a in self.layout.goal(observations))
        ranges, angles = self._sectors(scan)
        open_ = self._open(ranges, angles, np.minimum(distance, self.lookahead))
        wanted = np.clip(bearing - self.right_bias * (distance > 1.0), angles[0], angles[-1])
        cost = np.abs(angles[None] - wanted[:, None]) + np.where(open_, 0.0, np.inf)
        aim = angles[np.argmin(cost, axis=1)]
        blocked = ~open_.any(axis=1)
        behind = np.abs(bearing) > self.layout.fov / 2
        aim = np.where(behind, bearing, aim)
        half = ranges.shape[1] // 2
        roomier_left = ranges[:, half:].mean(axis=1) > ranges[:, :half].mean(axis=1)
        aim = np.where(blocked & ~behind, np.where(roomier_left, np.pi / 2, -np.pi / 2), aim)
        turn = np.clip(self.gain * aim, -self.max_turn, self.max_turn)
        ahead = np.abs(angles) < np.arctan2(self.radius + self.margin, self.slow_range)
        clearance = np.where(ahead, ranges, np.inf).min(axis=1) - self.radius
        speed = self.max_speed * np.clip(clearance / self.slow_range, 0.0, 1.0) * np.clip(np.cos(aim), 0.0, 1.0)
        speed = np.minimum(speed, distance)
        speed = np.where(blocked | behind, 0.0, speed)
        return np.column_stack([speed, turn])

    def _sectors(self, scan: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The scan pooled into at most :data:`SECTORS` sectors: nearest range and middle angle of each."""
        beams = scan.shape[1]
        starts = np.linspace(0, beams, min(beams, SECTORS) + 1).astype(np.int64)[:-1]
        ranges = np.minimum.reduceat(scan, starts, axis=1)
        ends = np.append(starts[1:], beams) - 1
        angles = self.layout.beam_angles
        return ranges, (angles[starts] + angles[ends]) / 2

    def _open(self, ranges: np.ndarray, angles: np.ndarray, needed: np.ndarray) -> np.ndarray:
        """(A, S) whether the body fits along each sector's direction for ``needed`` metres (per agent).

        A sector at range r narrows the directions within asin(w / r) of it, w the widened half-width."""
        gap = np.abs(angles[:, None] - angles[None, :])
        spread = np.arcsin(np.clip((self.radius + self.margin) / np.maximum(ranges, 1e-6), 0.0, 1.0))
        near = ranges[:, None, :] * np.cos(np.minimum(gap, np.pi / 2))[None] < needed[:, None, None]
        return ~np.any((gap[None] <= spread[:, None, :]) & near, axis=2)
