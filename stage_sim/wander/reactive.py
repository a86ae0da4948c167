"""Reactive wandering for a laser-equipped mobile robot: the decision logic of the ``wander`` node, ROS-free.

Per scan, :class:`Wanderer` (1) turns the scan into obstacle points and keeps the nearby ones that have left
the laser's field of view, with a safety allowance for odometry drift (:class:`ObstacleMemory`); (2) picks a
desired heading: *explore* heads for the open direction with the most space the robot has not yet passed near
(a coarse :class:`VisitMap` of the odometry frame, forgotten after a while so that wandering never ends); when
none is in view it *seeks*: follows the shortest route through the free space its laser has shown it
(:class:`SeenSpace`) to the nearest place not yet visited, such as a room glimpsed through a door; with none
left a *tour* takes the open direction nearest round to one side (a left- or right-hand rule: through every
door and round every room), the side redrawn by a seeded generator; (3) picks, from a fixed set of velocity
commands, the one that best serves that heading while the body, simulated along the command's arc, keeps
clear of every point (:class:`ArcPlanner`, a dynamic-window check). No command is ever zero, and none brings
the body closer to a point than ``safety_distance`` (or than it already is), so it never drives into what it
has seen; other robots, which back up blind, get a wider berth and are got away from when they come on (a
reverse may then take the whole path the robot came by).
Dithering in place (no net motion for half a second) is broken by turning one way only (the other way once
that one is blocked), then by backing off 0.3 m; stuck for longer (a dead end too narrow to turn round in),
the robot gives up what lay ahead and retraces in reverse the path it last drove forward, the only ground
behind it known to be clear, until it can turn round. Should the simulator report a stall all the same (the
last move refused: something the laser did not show, such as another robot that came into the blind rear), a
reversing robot stops reversing for BUMPED_S and a turning one turns the other way: odometry would not show
that the body stands.
"""

from __future__ import annotations

import math

import numpy as np

from stage_sim.wander.arc_planner import TOLERANCE, ArcPlanner
from stage_sim.wander.config import WanderConfig
from stage_sim.wander.doorways import DoorPassage, Doorway, find_doorways
from stage_sim.wander.frames import compose
from stage_sim.wander.laser_reading import LaserReading, wrap
from stage_sim.wander.motion_history import TRAIL_STEP, MotionHistory
from stage_sim.wander.obstacle_memory import ObstacleMemory
from stage_sim.wander.seen_space import SeenSpace, route_heading
from stage_sim.wander.velocity_arcs import arc_poses
from stage_sim.wander.visit_map import VisitMap

OPEN_RANGE = 1.5  # m of free corridor ahead for an escape direction to count as open
BLOCKED_RANGE = 0.7  # m of free corridor below which an explore heading is abandoned
TOUR_RANGE = 1.0  # m of free corridor for a direction to count as open to the tour
TOUR_GAP = 0.17  # m beside the body that the tour's corridor keeps free: room to turn in place next to a wall
WALL_NEAR = 1.2  # m: a tour with no wall this near on its side goes straight on to find one
BEARINGS = np.radians(np.arange(-110, 111, 5))  # directions weighed for exploring and escaping
SAMPLES = np.arange(0.5, 5.01, 0.5)  # m along a direction where unvisited space is looked for
NEW_SPACE = 2.0  # m of unvisited space in a direction that makes it worth exploring
NEARNESS = 3.0  # m over which the weight of unvisited space falls by e when choosing where to explore
LOOK_S = 0.5  # s between looks for new space
GIVE_UP_RADIUS = 2.0  # m around a stuck spot whose new space is given up on
ESCAPE_S = 4.0  # s spent heading away from a dead end or a stuck spot
BACKING_S = 1.0  # s a reverse manoeuvre is kept up before driving forward again
DOOR_S = 30.0  # s to get through a narrow doorway before giving it up
DOOR_EXIT = 0.6  # m past a doorway at which its passage is over
DOOR_THROUGH = 0.3  # m past a doorway at which the body is through it (its passage may end early there)
DOOR_BEYOND = np.array([1.0, 2.0, 3.0])  # m past a doorway where new space is looked for
DOOR_RECENT_S = 120.0  # s: touring, a doorway is taken unless its far side was visited this recently
REVERSE_ROOM_MAX = 1.0  # m of the path just driven forward that a reverse may take back (the rear is blind)
RETREAT_S = 12.0  # s a retreat may last
COMMIT_S = 2.0  # s of turning one way only when dithering and unable to back out
BUMPED_S = 3.0  # s without reversing after the body touched something behind it
ROUTE_S = 3.0  # s a route to far new space is followed before it is planned afresh
ROUTE_AHEAD = 1.0  # m along the route of the point a seeking robot heads for
ROUTE_OFF = 1.0  # m off its route at which a seeking robot plans a new one
ROUTE_SPEED = 0.25  # m/s at least along a route: slower, its goal is given up (marked visited)
ROUTE_SLACK_S = 30.0  # s allowed on top of that for doors and other robots
GOAL_RADIUS = 1.0  # m around a goal given up on that counts as visited
DOOR_ROUTE_GAP = 0.3  # m off a doorway's axis within which a route through it passes


class Wanderer:
    """Decides a velocity command per scan; the same seed and inputs give the same commands."""

    def __init__(self, config: WanderConfig | None = None, seed: int | None = None) -> None:
        self.config = config or WanderConfig()
        self.rng = np.random.default_rng(seed)
        self.planner = ArcPlanner(self.config)
        boxes = self.planner.boxes
        self._front = float(boxes[:, 1].max())
        self._half_width = float(np.abs(boxes[:, 2:]).max())
        x_min, x_max, y_min, y_max = boxes[0]  # the chassis, sampled finely enough to touch every cell under it
        grid = np.meshgrid(np.linspace(x_min, x_max, 6), np.linspace(y_min, y_max, 5))
        self._body_points = np.stack([grid[0].ravel(), grid[1].ravel()], axis=-1)
        self.obstacles = ObstacleMemory(self.config.memory_radius)
        self._odometry = np.zeros(2)  # metres driven and net radians turned so far (odometry errors scale with these)
        self._pose: tuple[float, float, float] | None = None
        self._time = 0.0
        self.command = (0.0, 0.0, 0.0)
        self.visits = VisitMap(reach=self.config.visit_reach)
        self.seen = SeenSpace()
        self._route: np.ndarray | None = None  # seeking: the route (odometry frame) to the nearest new place
        self._route_until = -math.inf  # when the route is planned afresh
        self._goal: tuple[np.ndarray, float] | None = None  # the place being sought and when it is given up
        offsets = np.arange(-GIVE_UP_RADIUS, GIVE_UP_RADIUS + 0.01, self.visits.cell)
        disc = np.stack(np.meshgrid(offsets, offsets), axis=-1).reshape(-1, 2)
        self._give_up_disc = disc[np.hypot(disc[:, 0], disc[:, 1]) <= GIVE_UP_RADIUS]
        self._goal_disc = disc[np.hypot(disc[:, 0], disc[:, 1]) <= GOAL_RADIUS]
        self.mode = "explore"  # or "seek", "tour", or "door" while passing self._door
        self._door: DoorPassage | None = None
        self._door_widths = (2 * (self._half_width + self.config.safety_distance) + 0.02,
                             2 * (self._half_width + TOUR_GAP) + 0.05)  # narrower than explore and tour see
        self._side = 1.0  # +1: the tour keeps the wall on the left
        self._tour_until = -math.inf
        self._tour_turn = 0.0  # net heading change of the current tour
        self._retarget_at = -math.inf
        self._heading = 0.0  # explore (or escape) heading in the odometry frame
        self._escape_until = -math.inf
        self._backing_until = -math.inf
        self._reverse_room = 0.0  # m the robot may back up: along the path it came, never into unseen space
        self.history = MotionHistory()
        self._retreat_until = -math.inf  # backing out along the trail until then (or until free to turn)
        self._retreat_gave_up = False  # the retreat abandons what lay ahead (else it only makes room for another try)
        self._commit = (-math.inf, 1.0)  # until when turns must go the one way given (+1: left)
        self._wedged_until = -math.inf  # no way back at all: until then the planner may keep half its margins
        self._rear_blocked_until = -math.inf  # touched something behind: no reversing until then

    def decide(
        self, reading: LaserReading, time: float, pose: tuple[float, float, float] | None = None,
        stalled: bool = False,
    ) -> tuple[float, float, float]:
        """The command (vx, vy, wz) for this scan; ``pose`` is odometry (dead reckoning if None); ``stalled``:
        the simulator refused the last move (the body touches something)."""
        pose = self._advance(time) if pose is None else tuple(float(v) for v in pose)
        if self._pose is not None:
            turn = float(wrap(pose[2] - self._pose[2]))
            self._odometry += (math.hypot(pose[0] - self._pose[0], pose[1] - self._pose[1]), turn)
            forward = math.cos(self._pose[2]) * (pose[0] - self._pose[0]) + math.sin(self._pose[2]) * (
                pose[1] - self._pose[1])
            self._reverse_room = min(max(self._reverse_room + forward, 0.0), REVERSE_ROOM_MAX)
            self._tour_turn += turn
            self.history.extend_trail(pose, forward)
        self._pose, self._time = pose, time
        points, allowance, moving, robot = self.obstacles.update(reading, pose, self._odometry, time,
                                                                 self.seen.never_occupied)
        self.visits.stamp(pose[0], pose[1], time)
        self._see(reading, pose)
        if self.history.stuck(time, pose):  # give up on new space around here, back out, then head somewhere else
            self._retreat(time, pose, give_up=True)
        elif self.history.standing_still(time, pose, float(self._odometry[1]), time < self._retreat_until):
            if self._door is not None and self._door.progress(pose)[0] > DOOR_THROUGH:
                self._leave_door(time, given_up=False)  # through, yet not out along the axis: carry on from here
            elif time < self._commit[0]:  # turning one way did not get it going either: back off a little
                if self._door is not None and self._door.progress(pose)[0] < 0:  # wedged before the doorway:
                    self._leave_door(time, given_up=True)  # it cannot be entered from here, give it up
                self._retreat(time, pose, give_up=False)
            else:  # dithering between turns: turn one way only for a while
                self._commit_turn(time)
        if stalled:  # after the standing-still rules, whose turn commitment would repeat the bumping turn
            self._bumped(time)
        if time < self._retreat_until:
            command = self._retreat_command(points, allowance, moving, robot, pose, time)
            if command is not None:
                self.command = command
                return command
        heading = None
        if time >= self._escape_until:
            self._choose_mode(time, points, pose, reading)
            if self.mode == "door":
                heading = self._door_heading(reading, pose, time)
            if self.mode == "seek":
                heading = route_heading(self._route, pose, ROUTE_AHEAD)[0]
            if self.mode == "tour":
                heading = self._tour_heading(points)
                if heading is None:  # a dead end: turn round, away from the wall
                    self._escape(time, wrap(pose[2] - self._side * (math.pi - 0.3)))
        if heading is None:
            heading = self._explore_heading(points, pose)
        self.command = self._plan(points, allowance, moving, robot, heading, time)
        return self.command

    def _advance(self, time: float) -> tuple[float, float, float]:
        """Dead reckoning from the last command when no odometry is given."""
        if self._pose is None:
            return (0.0, 0.0, 0.0)
        step = arc_poses(np.array([self.command]), np.array([max(0.0, time - self._time)]))[0, 0]
        x, y = compose(self._pose, step[None, :2])[0]
        return (float(x), float(y), float(wrap(self._pose[2] + step[2])))

    def _see(self, reading: LaserReading, pose: tuple) -> None:
        """Add the scan to the map of seen space: beams that hit or reached their range limit (NaN and
        too-near readings say nothing)."""
        ranges = np.asarray(reading.ranges, dtype=np.float64)
        hit = reading.hits()
        valid = hit | (ranges >= reading.range_max)  # includes +inf
        ends = compose(pose, reading.beam_ends(np.where(hit, ranges, reading.range_max))[valid])
        origin = compose(pose, np.array([reading.laser_pose[:2]]))[0]
        self.seen.observe(origin, ends, hit[valid], compose(pose, self._body_points))

    def _retreat(self, time: float, pose: tuple[float, float, float], give_up: bool) -> None:
        """Start backing out along the trail; giving up, what lay ahead counts as visited so it is not tried
        again at once, and the retreat goes on until the robot can turn round."""
        if give_up:
            if self._door is not None:
                self._leave_door(time, given_up=True)
            self.visits.mark(np.array(pose[:2]) + self._give_up_disc, time)
        self._retreat_gave_up = give_up
        self._retreat_until = time + RETREAT_S
        self.history.start_retreat(pose)

    def _bumped(self, time: float) -> None:
        """The last command ran the body into something the laser did not show: reversing, something behind
        it (another robot that came into the blind rear): no more reversing for a while, the retreat or
        backing spell is over; turning, a rear corner swung into it: turn the other way for a while."""
        vx, _, wz = self.command
        if vx < 0:  # the way it came is no longer known to be clear
            self._rear_blocked_until = time + BUMPED_S
            self._retreat_until = self._backing_until = -math.inf
            self._reverse_room = 0.0
        elif wz != 0:
            self._commit = (time + COMMIT_S, -1.0 if wz > 0 else 1.0)

    def _commit_turn(self, time: float) -> None:
        """Turn only the way the robot is turning now, for COMMIT_S (dithering between the two ends nowhere)."""
        self._commit = (time + COMMIT_S, 1.0 if self.command[2] >= 0 else -1.0)

    def _retreat_command(
        self, points: np.ndarray, allowance: np.ndarray, moving: np.ndarray, robot: np.ndarray, pose: tuple,
        time: float,
    ) -> tuple[float, ...] | None:
        """The next reverse command of the retreat; None once it is over (then, giving up, escape somewhere
        open; with no way back at all, turn one way only for a while)."""
        turn_free = self.planner.radius + self.config.safety_distance + TOLERANCE
        free_to_turn = np.hypot(points[:, 0], points[:, 1]).min(initial=np.inf) > turn_free
        speed = float(self.planner.commands[:, 0].min())
        steer = self.history.retreat_turn(pose, speed, free_to_turn, until_free=self._retreat_gave_up)
        if steer is not None:
            command = self._plan(points, allowance, moving, robot, math.pi, time, retreat_turn=steer)
            if command[0] < 0:
                return command
        self._retreat_until = -math.inf
        self.history.forget_recent()  # standing still is judged afresh from here
        if self.history.backed(pose) < TRAIL_STEP:
            self._commit_turn(time)
            self._wedged_until = self._commit[0]
        if self._retreat_gave_up:
            self._escape(time, self._pick_heading(points, pose))
        return None

    # -- behaviours -------------------------------------------------------------------------------

    def _choose_mode(self, time: float, points: np.ndarray, pose: tuple, reading: LaserReading) -> None:
        """Through a narrow doorway with new space behind it, else explore towards new space in view (both
        looked for every LOOK_S), else tour (side redrawn now and then)."""
        if self.mode == "door":
            return
        blocked = self.mode == "explore" and self._blocked(points, pose)
        if time < self._retarget_at and not blocked:
            return
        if blocked:  # what lay ahead cannot be reached from here: do not come back for it at once
            ahead = SAMPLES[BLOCKED_RANGE + self._front + 0.5 >= SAMPLES]
            self.visits.mark(np.stack([pose[0] + ahead * math.cos(self._heading),
                                       pose[1] + ahead * math.sin(self._heading)], axis=-1), time)
        self._retarget_at = time + LOOK_S
        self._door = self._door_to_take(reading, pose, time)
        if self._door is not None:
            self.mode = "door"
            return
        novelty, value = self._novelty(points, pose, time)
        if novelty.max() >= NEW_SPACE:
            value = np.where(novelty >= NEW_SPACE, value, 0.0)
            current = np.argmin(np.abs(wrap(BEARINGS + pose[2] - self._heading)))
            if self.mode != "explore" or value[current] < 0.5 * value.max():
                weights = value**3
                self._heading = float(wrap(pose[2] + self.rng.choice(BEARINGS, p=weights / weights.sum())))
            self.mode = "explore"
        elif self._seek(time, pose):
            self.mode = "seek"
        elif (self.mode in ("explore", "seek") or time >= self._tour_until
              or self._side * self._tour_turn >= 2 * math.pi):  # a full turn towards the wall: circling an island
            self.mode, self._tour_turn = "tour", 0.0
            self._tour_until = time + self.rng.uniform(*self.config.tour_s)
            self._side = float(self.rng.choice((-1.0, 1.0)))

    def _seek(self, time: float, pose: tuple) -> bool:
        """Whether there is a route to follow to new space out of view (planned afresh every ROUTE_S, when
        its goal has been visited or the robot is off it); a goal not reached in time is given up."""
        since = time - self.config.visit_memory_s
        route = self._route
        if route is None and time < self._route_until:  # none found lately: do not search on every look
            return False
        if (route is not None and time < self._route_until and route_heading(route, pose, 0.0)[1] < ROUTE_OFF
                and not self.visits.visited_since(route[-1:], since)[0]):
            return True
        self._route = route = self.seen.route(pose[:2], lambda xy: ~self.visits.visited_since(xy, since))
        self._route_until = time + ROUTE_S
        if route is None:
            return False
        length = float(np.hypot(*np.diff(route, axis=0).T).sum())
        if self._goal is None or np.hypot(*(route[-1] - self._goal[0])) > GOAL_RADIUS:  # a new goal
            self._goal = (route[-1], time + length / ROUTE_SPEED + ROUTE_SLACK_S)
        elif time > self._goal[1]:  # the same goal for too long: it cannot be reached from here
            self.visits.mark(route[-1] + self._goal_disc, time)
            self._route = None
            return False
        return True

    def _doorways(self, reading: LaserReading) -> list[Doorway]:
        return find_doorways(reading, *self._door_widths)

    def _door_to_take(self, reading: LaserReading, pose: tuple, time: float) -> DoorPassage | None:
        """The nearest narrow doorway in view whose far side is new (or, touring, not visited lately)."""
        since = time - (DOOR_RECENT_S if self.mode == "tour" else self.config.visit_memory_s)
        passages = [DoorPassage.seen_from(doorway, pose, time + DOOR_S) for doorway in self._doorways(reading)]
        fresh = [p for p in passages if (~self.visits.visited_since(p.beyond(DOOR_BEYOND), since)).sum() >= 2
                 or (self.mode == "seek" and self._route is not None and p.crossed_by(self._route, DOOR_ROUTE_GAP))]
        return min(fresh, key=lambda p: -p.progress(pose)[0], default=None)

    def _door_heading(self, reading: LaserReading, pose: tuple, time: float) -> float | None:
        """Relative heading along the doorway's axis; None once through (or given up after DOOR_S)."""
        door = self._door
        door.refine(self._doorways(reading), pose)
        along, _ = door.progress(pose)
        if along > DOOR_EXIT or time > door.until:
            self._leave_door(time, given_up=along <= DOOR_EXIT)
            return None
        return float(wrap(door.heading(pose) - pose[2]))

    def _leave_door(self, time: float, given_up: bool) -> None:
        """Back to exploring; a doorway given up on has its far side marked visited so it is not retried at once."""
        if given_up:
            self.visits.mark(self._door.beyond(DOOR_BEYOND), time)
        self._door, self.mode, self._retarget_at = None, "explore", -math.inf

    def _novelty(self, points: np.ndarray, pose: tuple, time: float) -> tuple[np.ndarray, np.ndarray]:
        """Metres of not recently visited space the robot could reach along each of BEARINGS, and the same
        with nearer space weighing more (so that the robot takes the door it passes before far corridors)."""
        reach = self._free_distance(points, BEARINGS) + self._front + 0.5
        x, y = SAMPLES * np.cos(BEARINGS)[:, None], SAMPLES * np.sin(BEARINGS)[:, None]
        world = compose(pose, np.stack([x.ravel(), y.ravel()], axis=-1)).reshape(*x.shape, 2)
        new = ~self.visits.visited_since(world, time - self.config.visit_memory_s) & (reach[:, None] >= SAMPLES)
        step = SAMPLES[1] - SAMPLES[0]
        return new.sum(axis=1) * step, (new * np.exp((SAMPLES[0] - SAMPLES) / NEARNESS)).sum(axis=1) * step

    def _escape(self, time: float, heading: float) -> None:
        """Cruise towards ``heading`` (odometry frame) for a few seconds, whatever the episode."""
        self._escape_until = time + ESCAPE_S
        self._heading = heading

    def _free_distance(self, points: np.ndarray, bearings: np.ndarray, half: float | None = None) -> np.ndarray:
        """How far (m) a corridor of half-width ``half`` (default: the body's + 0.1 m) is free along each bearing."""
        front, half_width = self._front, self._half_width
        half = half_width + 0.1 if half is None else half
        c, s = np.cos(bearings)[:, None], np.sin(bearings)[:, None]
        along = c * points[:, 0] + s * points[:, 1]
        blocking = (along > 0) & (np.abs(c * points[:, 1] - s * points[:, 0]) < half)
        return np.where(blocking, along - front, np.inf).min(axis=1, initial=np.inf)

    def _pick_heading(self, points: np.ndarray, pose: tuple) -> float:
        """A random open direction (odometry frame), favouring deep ones; a turn-around if none is open."""
        free = np.minimum(self._free_distance(points, BEARINGS), 6.0)
        weights = np.where(free >= OPEN_RANGE, free**2, 0.0)
        if weights.sum() == 0:
            return float(wrap(pose[2] + self.rng.choice((-1, 1)) * self.rng.uniform(2.0, math.pi)))
        return float(wrap(pose[2] + self.rng.choice(BEARINGS, p=weights / weights.sum())))

    def _blocked(self, points: np.ndarray, pose: tuple) -> bool:
        """Whether the explore heading, when in view, runs into something within BLOCKED_RANGE."""
        relative = wrap(self._heading - pose[2])
        return abs(relative) < BEARINGS[-1] and self._free_distance(points, np.array([relative]))[0] < BLOCKED_RANGE

    def _explore_heading(self, points: np.ndarray, pose: tuple) -> float:
        """Relative heading towards the explore (or escape) heading, redrawn at random when blocked."""
        if self._blocked(points, pose):
            self._heading = self._pick_heading(points, pose)
        return float(wrap(self._heading - pose[2]))

    def _tour_heading(self, points: np.ndarray) -> float | None:
        """The open direction nearest round to the followed side (a left/right-hand rule), None in a dead end.

        Open means a corridor TOUR_GAP wider than the body on each side is free for TOUR_RANGE, so the robot
        takes every door and corner on its side; with no wall within WALL_NEAR on that side it goes straight
        on until it meets one.
        """
        bearing = np.arctan2(points[:, 1], points[:, 0]) * self._side
        if not ((bearing > 0) & (np.hypot(points[:, 0], points[:, 1]) < WALL_NEAR)).any():
            return 0.0
        bearings = self._side * np.radians(np.arange(100, -101, -5))
        open_ = np.flatnonzero(self._free_distance(points, bearings, self._half_width + TOUR_GAP) >= TOUR_RANGE)
        return float(bearings[open_[0]]) if len(open_) else None

    # -- the safety-checked choice -----------------------------------------------------------------

    def _plan(
        self, points: np.ndarray, allowance: np.ndarray, moving: np.ndarray, robot: np.ndarray, heading: float,
        time: float, retreat_turn: float | None = None,
    ) -> tuple[float, ...]:
        """The best command for ``heading`` whose arc keeps clear (:class:`ArcPlanner`; ``moving`` and ``robot``
        flag the points as it takes them); a reverse chosen other than in a retreat or a tight spot starts a spell
        of backing up."""
        retreating = retreat_turn is not None
        backing = retreating or time < self._backing_until
        trail = self.history.trail_length(self._pose)
        room = trail if retreating else self._reverse_room
        if time < self._rear_blocked_until:
            room = trail = 0.0
        best = self.planner.choose(
            points, allowance, moving, heading, previous_turn=self.command[2], door=self.mode == "door",
            backing=backing, turn_sign=self._commit[1] if time < self._commit[0] else 0.0, reverse_room=room,
            retreat_turn=retreat_turn, wedged=time < self._wedged_until, robot=robot, flee_room=trail)
        command = self.planner.commands[best]
        if command[0] < 0 and not backing:
            self._backing_until = time + BACKING_S
        until, sign = self._commit
        if time < until and not retreating and self.planner.against(sign)[best]:
            self._commit = (until, -sign)  # the way committed to is blocked: the other way it is
        return tuple(float(v) for v in command)
