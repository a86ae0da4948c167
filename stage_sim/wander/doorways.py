"""Doorways in a laser scan: narrow openings between two near edges, with deep space behind them.

A doorway shows in a scan as a run of beams that reach much further than the beams on either side of it:
the last near hit before the run and the first after it are the door jambs, and what the run sees must
spread wider than the opening (a room, not a dead-end pocket). The wanderer's explore logic
looks for free corridors along a few dozen bearings, which misses openings barely wider than the body (a
corridor of the body's width lines up with such a door from only a sliver of positions), so doors that
narrow are found here from the scan itself and passed by following the door's axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stage_sim.wander.laser_reading import LaserReading

JUMP = 0.4  # m a beam must reach beyond its neighbour to open (or close) a run through an opening
DEPTH = 0.8  # m the run must reach beyond the jambs for the opening to lead somewhere
MAX_RANGE = 4.0  # m beyond which jambs are too coarsely seen to aim at
WALL_BEAMS = 5  # beams of wall beside the near jamb that give the wall's direction
STRAIGHT = 0.03  # m those wall points may stray from a line
SPREAD = 0.2  # m the space seen through an opening must reach beside its jambs for it to lead into a room
OBLIQUE = math.cos(math.radians(75))  # least cosine between the line of sight and the normal
REFIND_RADIUS = 0.35  # m a doorway seen again may have moved (odometry drift, a better view)
PURSUIT_MIN = 0.15  # m: nearer the door than this the robot steers onto the axis at its sharpest


@dataclass(frozen=True)
class Doorway:
    """An opening in the frame of the scan's points: its centre, the unit normal pointing through it away from
    the sensor, and the distance between the jambs."""

    center: np.ndarray
    normal: np.ndarray
    width: float


def find_doorways(reading: LaserReading, min_width: float, max_width: float) -> list[Doorway]:
    """The openings between ``min_width`` and ``max_width`` wide that the scan looks through.

    Seen obliquely, the far jamb shows its side face rather than its corner, so the wall's direction comes
    from the wall leading to the near jamb (when WALL_BEAMS of it are straight) and the width is measured
    along that wall; otherwise from the line between the jambs.
    """
    hits = reading.hits()
    ranges = np.where(hits, np.asarray(reading.ranges, dtype=np.float64), reading.range_max)
    points = reading.beam_ends(ranges)
    step = np.diff(ranges)
    rises = np.flatnonzero(step > JUMP)  # beam i near, i + 1 far
    falls = np.flatnonzero(step < -JUMP)  # beam j far, j + 1 near
    origin = np.array(reading.laser_pose[:2])
    doorways = []
    for i in rises:
        after = falls[falls > i]
        if not len(after):
            break
        j = int(after[0])
        if not (hits[i] and hits[j + 1]) or max(ranges[i], ranges[j + 1]) > MAX_RANGE:
            continue
        if ranges[i + 1: j + 1].max() - max(ranges[i], ranges[j + 1]) < DEPTH:
            continue  # a niche, not a way through
        near, far = (i, j + 1) if ranges[i] <= ranges[j + 1] else (j + 1, i)
        wall = points[near - WALL_BEAMS: near + 1] if near == i else points[near: near + WALL_BEAMS + 1]
        direction = points[far] - points[near]
        if len(wall) == WALL_BEAMS + 1:
            along = wall[-1] - wall[0] if near == i else wall[0] - wall[-1]
            along = along / max(np.hypot(*along), 1e-9)
            off_line = (wall - wall[0]) @ np.array([-along[1], along[0]])
            if np.abs(off_line).max() < STRAIGHT and along @ direction > 0:
                direction = along * (along @ direction)
        width = float(np.hypot(*direction))
        if not min_width <= width <= max_width:
            continue
        center = points[near] + direction / 2
        normal = np.array([-direction[1], direction[0]]) / width
        sight = center - origin
        if normal @ sight < 0:
            normal = -normal
        if normal @ sight < OBLIQUE * np.hypot(*sight):
            continue  # seen at a grazing angle: jambs and width are guesses
        beyond = points[i + 1: j + 1] - center
        if np.abs(beyond @ np.array([-normal[1], normal[0]])).max() < width / 2 + SPREAD:
            continue  # no wider than the opening behind it: a dead-end pocket, not a way into a room
        doorways.append(Doorway(center, normal, width))
    return doorways


@dataclass
class DoorPassage:
    """A doorway being passed, in the odometry frame: steer onto its axis, then along it and through.

    The steering aims at the point of the axis half-way between the robot's projection on it and the door
    (pure pursuit), so the robot lines up before it reaches the jambs; each new scan that sees the doorway
    again refines its centre and normal (they are less certain the more obliquely they were first seen).
    """

    center: np.ndarray
    normal: np.ndarray
    until: float  # sim time at which the passage is given up

    @classmethod
    def seen_from(cls, doorway: Doorway, pose: tuple[float, float, float], until: float) -> DoorPassage:
        center, normal = in_odometry_frame(doorway, pose)
        return cls(center, normal, until)

    def beyond(self, distances: np.ndarray) -> np.ndarray:
        """Points (D, 2) on the far side, at these distances past the door along its normal."""
        return self.center + distances[:, None] * self.normal

    def refine(self, doorways: list[Doorway], pose: tuple[float, float, float]) -> None:
        """Take the centre and normal of the same doorway seen in this scan, if it is there."""
        for doorway in doorways:
            center, normal = in_odometry_frame(doorway, pose)
            if np.hypot(*(center - self.center)) < REFIND_RADIUS and normal @ self.normal > 0.8:
                self.center, self.normal = center, normal
                return

    def progress(self, pose: tuple[float, float, float]) -> tuple[float, float]:
        """(along, lateral): how far past the door the robot is along the normal, and how far off the axis."""
        along, lateral = self._in_door_frame(np.array(pose[:2]))
        return float(along), float(lateral)

    def crossed_by(self, path: np.ndarray, gap: float) -> bool:
        """Whether the path (P, 2) runs through the opening from one side to the other: within ``gap`` of the
        axis, from just before the door to just past it."""
        along, lateral = self._in_door_frame(path)
        close = (np.abs(lateral) < gap) & (np.abs(along) < 1.0)
        return bool((close & (along < -0.1)).any() and (close & (along > 0.1)).any())

    def _in_door_frame(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points (..., 2) as (along the normal past the door, off the axis)."""
        offset = points - self.center
        return offset @ self.normal, offset @ np.array([-self.normal[1], self.normal[0]])

    def heading(self, pose: tuple[float, float, float]) -> float:
        """The heading (odometry frame) that brings the robot onto the axis and through the door."""
        along, lateral = self.progress(pose)
        return math.atan2(self.normal[1], self.normal[0]) - math.atan2(lateral, max(-along / 2, PURSUIT_MIN))


def in_odometry_frame(doorway: Doorway, pose: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    """A doorway seen from ``pose``: its centre and normal in the frame of the pose."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    rotation = np.array([[c, -s], [s, c]])
    return np.array(pose[:2]) + rotation @ doorway.center, rotation @ doorway.normal
