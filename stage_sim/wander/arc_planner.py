"""The wanderer's safety-checked choice of a velocity command: a dynamic-window check of a fixed command set.

Each candidate command is followed along its exact arc (:func:`arc_poses`) for 1.5 s; an arc is clear while
the body rectangles keep ``safety_distance`` (plus each point's odometry-drift allowance, plus room that grows
at ``moving_speed`` for points seen moving in) from every obstacle point, and a point already nearer than that
may come no nearer (a body moving in close must be got away from). Another robot's body gets a wider berth: it
may back up blind at any moment. Among the arcs that stay clear long enough, the one that best serves the
desired heading, keeps clearance and leaves room to turn round wins; no command is ever zero.
"""

from __future__ import annotations

import math

import numpy as np

from stage_sim.wander import kernels
from stage_sim.wander.config import WanderConfig
from stage_sim.wander.frames import first_per_cell
from stage_sim.wander.velocity_arcs import arc_poses, candidate_commands

# Candidate arcs are checked at these times (s): densely while the command is in force, sparser beyond.
CHECK_TIMES = np.array([0.1, 0.2, 0.3, 0.4, 0.6, 0.8, 1.1, 1.5])
SAFE_TIMES = np.concatenate([[0.0], CHECK_TIMES[:-1]])  # how long an arc stays clear if it hits at index k
TURN_CHECK = 4  # index in CHECK_TIMES of the pose (0.6 s) whose turning circle should be clear
ADMISSIBLE_S = 0.4  # an arc must stay clear this long to be chosen when any does
LOOK_AHEAD_S = 1.0  # heading and progress of a candidate are judged at this time
TOLERANCE = 0.005  # m a point already inside the safety distance may come closer (sensor quantisation)
CLEARANCE_CAP = 0.15  # m of clearance beyond which more is no better
CLEARANCE_WEIGHT = 2.5  # worth of that clearance against heading and progress (about 1 each)
PLAN_CELL = 0.02  # m: points are thinned to one per cell of this size for the arc checks
MAX_ALLOWANCE = 0.1  # m: points less certain than this are not planned with (the wanderer forgets them)
MOVER_MARGIN = 0.15  # m more kept from points taken for another robot: it may back up blind at any moment
FLEE_RANGE = 0.3  # m: a body moving in this near (FLEE_POINTS of its points at least) must be got away from...
FLEE_POINTS = 8  # ...(fewer moving points this near are quantisation at a wall or a jamb, not a body)...
FLEE_SPEED = 0.1  # m/s: ...at this speed (another robot backing up blind at 0.15 m/s will not stop for us)


class ArcPlanner:
    """The candidate commands of one robot and the geometry to check them: body rectangles and arc poses."""

    def __init__(self, config: WanderConfig) -> None:
        self.config = config
        self.commands = candidate_commands(config)
        self._poses = arc_poses(self.commands, CHECK_TIMES)
        self._look = arc_poses(self.commands, np.array([LOOK_AHEAD_S]))[:, 0]
        self.boxes = np.array(config.footprint, dtype=np.float64).reshape(-1, 4)
        boxes = self.boxes
        self.radius = float(np.hypot(np.abs(boxes[:, :2]).max(axis=1), np.abs(boxes[:, 2:]).max(axis=1)).max())
        # Candidates grouped by linear speed, with how far from the centre a point can matter to them.
        speeds = np.round(np.hypot(self.commands[:, 0], self.commands[:, 1]), 6)
        margin = config.safety_distance + MAX_ALLOWANCE + MOVER_MARGIN + CLEARANCE_CAP
        self._groups = [(v * CHECK_TIMES[-1] + self.radius + margin, np.flatnonzero(speeds == v))
                        for v in np.unique(speeds)]
        # The arc poses as the check reads them: positions, and the cosine and sine of each yaw computed
        # group by group exactly as the vectorised check did (a vectorised cosine may round differently by
        # position in the array).
        self._x, self._y = (np.ascontiguousarray(self._poses[:, :, k]) for k in range(2))
        self._cos, self._sin = np.empty_like(self._x), np.empty_like(self._x)
        for _, rows in self._groups:
            yaw = self._poses[rows, :, 2, None]
            self._cos[rows], self._sin[rows] = np.cos(yaw)[..., 0], np.sin(yaw)[..., 0]
        self._turn_x, self._turn_y = (np.ascontiguousarray(self._poses[:, TURN_CHECK, k]) for k in range(2))
        kernels.warm_up()

    def choose(
        self, points: np.ndarray, allowance: np.ndarray, moving: np.ndarray, heading: float, *,
        previous_turn: float, door: bool, backing: bool, turn_sign: float, reverse_room: float,
        retreat_turn: float | None = None, wedged: bool = False, robot: np.ndarray | None = None,
        flee_room: float | None = None,
    ) -> int:
        """Index of the best command for ``heading`` (robot frame) among those whose arc keeps clear.

        ``door``: passing a narrow doorway (little clearance, no room to turn: ask for less); ``backing``:
        getting out of a tight spot (half the margin will do, reversing is preferred); ``turn_sign``: turns
        (and sideways moves) the other way are penalised (0: none); ``reverse_room``: metres behind known to
        be clear (the laser does not see backwards); ``retreat_turn``: retreating, the reverse command nearest
        this turn rate wins if any is clear (and no allowance for odometry drift is made: the body has just been
        there).
        ``wedged``: the robot can neither back out nor get going by turning one way; then, when no arc keeps
        the margins beyond the first check time (the body already inside them, as where a retreat, which keeps
        only half of them, ended), the arcs are checked again against half the safety distance and no drift
        allowance, so that a robot wedged against a wall it may not come nearer still finds a way out.
        ``robot``: which points are taken for another robot's body (default none): MOVER_MARGIN more is kept from
        them (that robot may back up blind at any moment). A body moving in within FLEE_RANGE (FLEE_POINTS of its
        points, taken for a robot or not: one that stood still a while is part of the map) must be got away from
        at FLEE_SPEED (keeping the present distance does not do against a robot backing up blind) if any arc
        does so long enough; if none does, holding the present distance will do (asking the impossible made two
        robots that each took the other's dithering for coming on stand off for minutes). Fleeing, a reverse may
        take ``flee_room`` metres (the whole path the robot came by: another robot's blind retreat can be that long).
        """
        config = self.config
        # How near each point could come within the horizon: moving ones come nearer.
        distance = np.hypot(points[:, 0], points[:, 1]) - moving * config.moving_speed * CHECK_TIMES[-1]
        near = distance < self._groups[-1][0]
        thin = first_per_cell(points[near], PLAN_CELL)
        order = thin[np.argsort(distance[near][thin])]
        points, allowance, distance = points[near][order], allowance[near][order], distance[near][order]
        moving = moving[near][order]
        robot = np.zeros(len(points), dtype=bool) if robot is None else robot[near][order]
        now = self.body_distance(points[:, 0], points[:, 1])
        retreating = retreat_turn is not None
        if retreating:
            allowance = np.zeros_like(allowance)
        approach = np.outer(CHECK_TIMES, moving * config.moving_speed)  # (T, P): room for points moving in
        closing = moving & (now < FLEE_RANGE)
        margin = config.safety_distance * (0.5 if backing else 1.0) + allowance + MOVER_MARGIN * robot
        # Passes of (margin, least distance (T, P) for points already inside it, reverse room, fleeing), until one
        # leaves something to do: getting away from a body moving in (its nearest point's distance growing), if
        # any arc does; else holding the present distance; wedged, half margins.
        hold = np.broadcast_to(now - TOLERANCE, (len(CHECK_TIMES), len(now)))
        passes = [(margin, hold, reverse_room, False)]
        if closing.sum() >= FLEE_POINTS:
            away = now[closing].min() - TOLERANCE + FLEE_SPEED * CHECK_TIMES[:, None]
            room = reverse_room if flee_room is None else max(reverse_room, flee_room)
            passes.insert(0, (margin, np.where(closing, away, hold), room, True))
        if wedged and not retreating:  # inside those margins (where a retreat, which keeps half, ended): half, no drift
            passes.append((np.full_like(allowance, 0.5 * config.safety_distance), hold, reverse_room, False))
        counts = np.empty(len(self.commands), dtype=np.int64)
        for reach, rows in self._groups:  # a slow arc only needs the points it can reach
            counts[rows] = np.searchsorted(distance, reach)
        px, py = np.ascontiguousarray(points[:, 0]), np.ascontiguousarray(points[:, 1])
        speed = self.commands[:, 0]
        for margin, least, room, fleeing in passes:
            reversible = (speed >= 0) | (-speed * ADMISSIBLE_S <= room)
            keep_off = margin + approach
            limit = np.where(now > keep_off, keep_off, np.minimum(least, keep_off))
            # (C, T): least margin to any point; < 0 is a hit (and what follows a hit is not looked at)
            closest = kernels.arc_margins(self._x, self._y, self._cos, self._sin, counts, px, py, distance,
                                          np.ascontiguousarray(limit), self.boxes, self.radius)
            hit = np.logical_or.accumulate(closest < 0, axis=1)
            safe_until = np.where(hit.any(axis=1), SAFE_TIMES[np.argmax(hit, axis=1)], CHECK_TIMES[-1])
            admissible = (safe_until >= ADMISSIBLE_S) & reversible
            if admissible.any():
                break  # something stays clear long enough
            if not fleeing and np.where(reversible, safe_until, 0.0).max() > CHECK_TIMES[0]:
                break  # of what may be done (no fleeing asked), the longest clear
        clearance = np.where(hit, np.inf, closest).min(axis=1)
        look_x, look_y, look_yaw = self._look.T
        progress = (look_x * math.cos(heading) + look_y * math.sin(heading)) / (config.forward_speed * LOOK_AHEAD_S)
        score = (np.cos(heading - look_yaw) + progress + safe_until / CHECK_TIMES[-1]
                 + (0.5 if door else CLEARANCE_WEIGHT) * np.minimum(clearance, CLEARANCE_CAP) / CLEARANCE_CAP
                 - 0.2 * np.abs(self.commands[:, 2] - previous_turn) / config.turn_rate
                 - (1.0 if door else 8.0) * self._cramped(px, py, distance)
                 - np.where(backing, speed > 0, speed < 0)  # reverse only to get out, then only until free
                 - 3.0 * self.against(turn_sign))
        if retreating and (admissible & (speed < 0)).any():
            admissible &= speed < 0
            score = -np.abs(self.commands[:, 2] - retreat_turn) - np.abs(self.commands[:, 1])
        if not admissible.any():  # nothing stays clear long enough: of what may be done, whatever stays clear
            longest = np.where(reversible, safe_until, -1.0)  # longest, then with least intrusion in its first step
            admissible = longest == longest.max()
            score = closest[:, 0]
        return int(np.argmax(np.where(admissible, score, -np.inf)))

    def against(self, turn_sign: float) -> np.ndarray:
        """Which commands (C,) turn or move sideways against ``turn_sign`` (+1: left; 0: none do)."""
        return (self.commands[:, 2] * turn_sign < 0) | (self.commands[:, 1] * turn_sign < 0)

    def _cramped(self, px: np.ndarray, py: np.ndarray, near: np.ndarray) -> np.ndarray:
        """How far (m) points intrude into the turning circle at each candidate's half-second pose (C,); the
        points (``px``, ``py``) no farther than ``near`` from the origin and sorted by it."""
        nearest = kernels.nearest_distance(self._turn_x, self._turn_y, px, py, near)
        return np.maximum(self.radius + self.config.safety_distance - nearest, 0.0)

    def body_distance(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Distance from body-frame points to the body (0 inside): the nearest of its rectangles."""
        distance = None
        for x_min, x_max, y_min, y_max in self.boxes:
            dx = np.maximum(np.maximum(x - x_max, x_min - x), 0.0)
            dy = np.maximum(np.maximum(y - y_max, y_min - y), 0.0)
            box = np.hypot(dx, dy)
            distance = box if distance is None else np.minimum(distance, box)
        return distance

