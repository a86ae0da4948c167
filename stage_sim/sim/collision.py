"""Robot bodies on the grid: where their outlines fall, and which moves Stage would refuse.

A robot's body is a cloud of outline points in its own frame (see :mod:`stage_sim.sim.robots`).
Placing all robots is one vectorised transform of all points; the cells they fall in are checked against
the static collision layer (in tiles, :class:`~stage_sim.maps.tiles.TileLayer`) and against each other by
the cells they share (sorted (cell, robot) pairs, or a hash table of the robots' cells in the compiled
path: memory in proportion to the robots' cells, 16-32 B each, never to the world's area). The cells of
every body at the accepted poses are kept up to date through the rounds of refusals (only the refused
robots' cells change) and handed to the lasers, which see the robots through the same cells. A clash
that a round leaves must involve a robot that round moved back (the others share the cells they had), so
the next round looks only at robots within touching distance of those; the first round, only at robots
within touching distance of another, and the compiled sweep looks at a body's points only where a region
holding a wall cell lies within its radius (neither narrowing changes a refusal). As in Stage,
a move that makes a body share a cell with an obstacle (a static cell with ``obstacle_return`` or another
robot) is undone and the robot is marked stalled. Moves longer than half the body's width are checked at
intermediate poses so that no speed the bounds allow can carry a body through a wall one cell thick.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from stage_sim.maps.polygon_raster import point_cells
from stage_sim.maps.tiles import TileLayer, unique_sorted
from stage_sim.sim.kinematics import integrate

# Robot-robot conflicts can cascade (a refused move leaves a robot where another one just moved); a few
# rounds settle every realistic case, after which all robots still in conflict are refused together.
MAX_CONFLICT_ROUNDS = 4
# Robots refused in a round times colliding robots up to which the next round's clash test is narrowed to
# the robots near the refused ones by a distance test (beyond, the test takes every colliding robot).
NARROWING_PAIRS = 200_000
def place(points: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """World coordinates of body points (P, 2), each given with the pose (P, 3) of its robot."""
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    px, py = points[:, 0], points[:, 1]
    out = np.empty((len(poses), 2))  # filled column by column: np.stack costs more than this for a few points
    out[:, 0] = poses[:, 0] + c * px - s * py
    out[:, 1] = poses[:, 1] + s * px + c * py
    return out


@dataclass
class Bodies:
    """All robots' outline points, concatenated, with the robot each point belongs to."""

    points: np.ndarray
    owner: np.ndarray
    count: int
    min_width: np.ndarray
    radius: np.ndarray

    @classmethod
    def from_outlines(cls, outlines: list[np.ndarray]) -> Bodies:
        """Bodies from per-robot outline point arrays (each (P_i, 2) in the robot frame)."""
        owner = np.concatenate([np.full(len(o), i, dtype=np.int64) for i, o in enumerate(outlines)] or [[]])
        points = np.concatenate(outlines) if outlines else np.zeros((0, 2))
        width = np.array([(o.max(axis=0) - o.min(axis=0)).min() if len(o) else 0.0 for o in outlines])
        radius = np.array([np.hypot(*o.T).max() if len(o) else 0.0 for o in outlines])
        return cls(points, owner.astype(np.int64), len(outlines), width, radius)


@dataclass(frozen=True)
class GridFrame:
    """Geometry of the world grid the bodies are placed on."""

    shape: tuple[int, int]
    resolution: float
    origin_xy: tuple[float, float]
    threads: int = 1  #: threads of the compiled loops over many items (the same answers for any)


class Contact(Protocol):
    """The contact role of a kernel backend (:mod:`stage_sim.sim.backends`): where the bodies lie, which moves
    are refused. :class:`CollisionChecker` is the numpy reference, and
    :class:`~stage_sim.sim.compiled.CompiledCollisionChecker` gives its answers bit for bit."""

    def resolve(self, poses: np.ndarray, velocities: np.ndarray, dt: float, moving: np.ndarray | None = None,
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Move every robot by one step: (new poses, refused, every body point's cell at the new poses)."""
        ...

    def overlapping(self, poses: np.ndarray) -> np.ndarray:
        """Robots whose bodies at ``poses`` already share a cell with a static obstacle or another robot."""
        ...

    def point_cells(self, poses: np.ndarray) -> np.ndarray:
        """Flat cell of every outline point with the robots at ``poses`` (N, 3); −1 outside the grid."""
        ...


class CollisionChecker:
    """Decides which robot moves to accept, given the static cells that block each robot's height band: the
    numpy reference of the :class:`Contact` role. The compiled backend overrides its hooks, with the same
    answers: ``_body_cells``, ``_moves``, ``_contains``, ``_replace_cells``, ``_close_to_another``, ``_close_to``
    and ``_clashes``."""

    def __init__(
        self, bodies: Bodies, grid: GridFrame, layers: list[TileLayer], layer_of_robot: np.ndarray,
        collides: np.ndarray,
    ) -> None:
        self.bodies = bodies
        self.grid = grid
        self._layers = layers
        self._layer_of_robot = layer_of_robot
        self._collides = collides
        self._robots_can_clash = int(np.count_nonzero(collides)) > 1
        counts = np.bincount(bodies.owner, minlength=bodies.count)
        self._point_count = counts
        self._point_start = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
        self._colliding = np.flatnonzero(collides)

    def resolve(
        self, poses: np.ndarray, velocities: np.ndarray, dt: float, moving: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Move every robot by one step; returns (new poses, refused, the cells of every body point at the new
        poses, as :meth:`point_cells`) with refused moves undone.

        Robots with zero velocity (``moving`` False, computed when not given) do not move and are never
        refused here; the caller keeps their previous stall flag, as Stage does."""
        moving = np.any(velocities != 0.0, axis=1) if moving is None else moving
        refused = np.zeros(len(poses), dtype=bool)
        movers = np.flatnonzero(moving & self._collides)
        candidates = self._moves(poses, velocities, dt, moving, movers, refused)
        final = np.where(refused[:, None], poses, candidates)
        cells = self.point_cells(final)
        if not self._robots_can_clash:
            return final, refused, cells
        among = self._crowded(final)
        for _ in range(MAX_CONFLICT_ROUNDS):
            conflict = self._clashes(cells, among) & moving & ~refused
            if not conflict.any():
                return final, refused, cells
            refused |= conflict
            final = np.where(refused[:, None], poses, candidates)
            moved_back = np.flatnonzero(conflict)
            self._replace_cells(cells, final, moved_back)
            among = self._near(moved_back, final)
        last = self._clashes(cells, among) & moving & ~refused
        refused |= last
        final = np.where(refused[:, None], poses, candidates)
        self._replace_cells(cells, final, np.flatnonzero(last))
        return final, refused, cells

    def overlapping(self, poses: np.ndarray) -> np.ndarray:
        """Robots whose bodies at ``poses`` already share a cell with a static obstacle or another robot."""
        everyone = np.flatnonzero(self._collides)
        touching = np.zeros(len(poses), dtype=bool)
        if everyone.size:
            touching[everyone] = self._hits_static(poses, np.zeros_like(poses), 0.0, everyone)
        if not self._robots_can_clash:
            return touching
        return touching | self._clashes(self.point_cells(poses), self._colliding)

    def point_cells(self, poses: np.ndarray) -> np.ndarray:
        """Flat cell of every outline point with the robots at ``poses`` (N, 3); −1 outside the grid."""
        return self._body_cells(self.bodies.points, self.bodies.owner, poses)

    def _body_cells(self, points: np.ndarray, pose_index: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """Flat cell of body point i (robot frame) placed at pose ``poses[pose_index[i]]``; −1 off the grid."""
        g = self.grid
        return point_cells(place(points, poses[pose_index]), g.resolution, g.origin_xy, g.shape)

    def _moves(
        self, poses: np.ndarray, velocities: np.ndarray, dt: float, moving: np.ndarray, movers: np.ndarray,
        refused: np.ndarray,
    ) -> np.ndarray:
        """The candidate poses of one step; marks in ``refused`` the movers whose sweep meets a static cell."""
        candidates = poses.copy()
        candidates[moving] = integrate(poses[moving], velocities[moving], dt)
        if movers.size:
            refused[movers] = self._hits_static(poses, velocities, dt, movers)
        return candidates

    def _points_of(self, robots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Indices of the outline points of each entry of ``robots`` and, per point, its entry number."""
        counts = self._point_count[robots]
        entry = np.repeat(np.arange(len(robots)), counts)
        first = np.repeat(self._point_start[robots] - (np.cumsum(counts) - counts), counts)
        return first + np.arange(counts.sum()), entry

    def _hits_static(self, poses: np.ndarray, velocities: np.ndarray, dt: float, movers: np.ndarray) -> np.ndarray:
        """Whether each mover's body meets a blocked cell at its new pose or at any intermediate pose."""
        step = np.hypot(velocities[movers, 0], velocities[movers, 1]) * dt
        sweep = step + np.abs(velocities[movers, 2]) * dt * self.bodies.radius[movers]
        limit = np.maximum(self.bodies.min_width[movers] / 2, self.grid.resolution)
        substeps = np.maximum(1, np.ceil(sweep / limit).astype(np.int64))
        robot = np.repeat(movers, substeps)
        fraction = (np.arange(len(robot)) - np.repeat(np.cumsum(substeps) - substeps, substeps) + 1) / np.repeat(
            substeps, substeps)
        probes = integrate(poses[robot], velocities[robot] * fraction[:, None], dt)
        point_index, probe = self._points_of(robot)
        cells = self._body_cells(self.bodies.points[point_index], probe, probes)
        point_robot = robot[probe]
        layer_index = self._layer_of_robot[point_robot]
        hit = np.zeros(len(cells), dtype=bool)
        for i, layer in enumerate(self._layers):
            use = (layer_index == i) & (cells >= 0)
            hit[use] = self._contains(layer, cells[use])
        return (np.bincount(point_robot[hit], minlength=self.bodies.count) > 0)[movers]

    def _contains(self, layer: TileLayer, cells: np.ndarray) -> np.ndarray:
        """Whether each flat cell is in the static layer."""
        return layer.contains(cells)

    def _replace_cells(self, cells: np.ndarray, poses: np.ndarray, robots: np.ndarray) -> None:
        """Put the cells of ``robots``' points (entries of :meth:`point_cells`) at ``poses`` into ``cells``."""
        if not robots.size:
            return
        point_index, entry = self._points_of(robots)
        cells[point_index] = self._body_cells(self.bodies.points[point_index], robots[entry], poses)

    def _crowded(self, poses: np.ndarray) -> np.ndarray:
        """The colliding robots within touching distance of another at ``poses`` (centres no farther apart than
        their radii and two cells): only these can share a cell, so the first clash test looks at these alone;
        every colliding robot when there are more than :data:`NARROWING_PAIRS` pairs to measure."""
        robots = self._colliding
        if robots.size * (robots.size - 1) // 2 > NARROWING_PAIRS:
            return robots
        return robots[self._close_to_another(robots, poses)]

    def _close_to_another(self, robots: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """Per robot of ``robots``: whether another of them is within touching distance at ``poses``."""
        close = self._touching(robots, robots, poses)
        np.fill_diagonal(close, False)
        return close.any(axis=1)

    def _near(self, robots: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """The colliding robots whose bodies at ``poses`` could share a cell with one of ``robots``' (centres no
        farther apart than their radii and two cells), ``robots`` included; all of them for many ``robots``."""
        if robots.size * self._colliding.size > NARROWING_PAIRS:
            return self._colliding
        return self._colliding[self._close_to(robots, poses)]

    def _close_to(self, robots: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """Per colliding robot: whether one of ``robots`` is within touching distance at ``poses``."""
        return self._touching(self._colliding, robots, poses).any(axis=1)

    def _touching(self, others: np.ndarray, robots: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """(others, robots) pairs whose centres at ``poses`` are no farther apart than their radii and two cells
        (the numpy path's distance matrix; the compiled one loops over the pairs)."""
        gap = poses[others, None, :2] - poses[None, robots, :2]
        reach = self.bodies.radius[others, None] + self.bodies.radius[None, robots] + 2 * self.grid.resolution
        return np.hypot(gap[..., 0], gap[..., 1]) <= reach

    def _clashes(self, cells: np.ndarray, among: np.ndarray) -> np.ndarray:
        """Robots of ``among`` (colliding robots) whose body points (``cells``, per body point) share a cell
        with another robot of ``among``."""
        conflict = np.zeros(self.bodies.count, dtype=bool)
        taking = np.zeros(self.bodies.count, dtype=bool)
        taking[among] = True
        keep = (cells >= 0) & taking[self.bodies.owner]
        robots = np.int64(self.bodies.count)
        pairs = unique_sorted(cells[keep] * robots + self.bodies.owner[keep])  # each (cell, robot) once, by cell
        shared = pairs[1:] // robots == pairs[:-1] // robots
        conflict[pairs[1:][shared] % robots] = True
        conflict[pairs[:-1][shared] % robots] = True
        return conflict
