"""Robot bodies on the grid as Stage rasterises them, and which moves Stage refuses.

**Bodies.** A robot's body is its blocks' polygons in the robot frame (see :mod:`stage_sim.sim.robots`). At
every pose each vertex is placed (``pose ⊕ vertex``, Stage's ``LocalToPixels``), floored to its world cell
(``floor(x · ppm)``) and each edge walked cell by cell (``World::MapPoly``, the walk the static blocks take:
:mod:`stage_sim.maps.polygon_raster`). Only edges exist, as in Stage. The casters and the contact test read
the same raster.

**Contacts** (Stage 4.3: ``World::Update``, ``ModelPosition::Move``, ``Block::TestCollision``). Stage keeps
two raster layers and on update ``k`` works in layer ``k % 2``: robots with a non-zero velocity move one by
one (Stage's order is its internal set order, by memory address; here robot index order, the closest
deterministic rule); each is re-rasterised at its end pose (no sweep along the path) and tested against the
static cells of its height band and the other obstacle robots' cells *in that layer*: those already moved
in this update at their new pose, the others where that layer last saw them (two updates ago when they
move every update). A refused move puts the robot back (re-rasterised there) and sets its stall flag; an
accepted one clears it; a robot with zero velocity is not touched (it keeps its flag). Rays read the layer
the moves just built (in Stage the sensors of update ``k + 1`` read layer ``k % 2``). The state is the
pose of every robot in each layer (:attr:`Simulation._layer_poses`); a checker keeps only the last few
rasters it made, which the same poses give again.

The numpy reference decides the moves from the pairs of robots sharing a cell (:func:`decide_moves`); the
compiled backend (:mod:`stage_sim.sim.compiled`) replays them one by one as Stage does, comparing cells only
between robots whose boxes meet, which needs no sorting. Both give the same answers, and the same raster bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from stage_sim.maps.polygon_raster import edge_cells_with_edges
from stage_sim.maps.tiles import TileLayer, unique_sorted
from stage_sim.sim.kinematics import integrate


def place(points: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """World coordinates of body points (P, 2), each given with the pose (P, 3) of its robot (Stage's
    ``pose + Pose(x, y)``: x + px·cos − py·sin, y + px·sin + py·cos)."""
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    px, py = points[:, 0], points[:, 1]
    out = np.empty((len(poses), 2))  # filled column by column: np.stack costs more than this for a few points
    out[:, 0] = poses[:, 0] + c * px - s * py
    out[:, 1] = poses[:, 1] + s * px + c * py
    return out


@dataclass
class Bodies:
    """All robots' body polygons in their robot frames, concatenated (robot r owns polygons
    ``robot_poly[r]`` to ``robot_poly[r + 1]``, polygon p vertices ``poly_start[p]`` to ``poly_start[p + 1]``)."""

    vertices: np.ndarray  #: (V, 2) float64
    poly_start: np.ndarray  #: (P + 1,) int64
    robot_poly: np.ndarray  #: (R + 1,) int64
    count: int
    radius: np.ndarray  #: (R,) farthest vertex from the robot origin

    @classmethod
    def from_polygons(cls, bodies: list[list[np.ndarray]]) -> Bodies:
        """Bodies from per-robot lists of polygons (each (M, 2) in the robot frame)."""
        polygons = [p for body in bodies for p in body]
        vertices = np.concatenate(polygons).astype(np.float64) if polygons else np.zeros((0, 2))
        sizes = [len(p) for p in polygons]
        poly_start = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        robot_poly = np.concatenate([[0], np.cumsum([len(b) for b in bodies])]).astype(np.int64)
        radius = np.array([max((np.hypot(*p.T).max() for p in body), default=0.0) for body in bodies])
        return cls(vertices, poly_start, robot_poly, len(bodies), radius)

    @property
    def vertex_robot(self) -> np.ndarray:
        """The robot of every vertex (V,)."""
        per_poly = np.repeat(np.arange(self.count), np.diff(self.robot_poly))
        return np.repeat(per_poly, np.diff(self.poly_start)).astype(np.int64)

    @property
    def next_vertex(self) -> np.ndarray:
        """Index of the vertex each edge ends at (V,): the next one of its polygon, the first after the last."""
        following = np.arange(1, len(self.vertices) + 1, dtype=np.int64)
        filled = self.poly_start[1:] > self.poly_start[:-1]
        following[self.poly_start[1:][filled] - 1] = self.poly_start[:-1][filled]
        return following


@dataclass(frozen=True)
class GridFrame:
    """Geometry of the world grid the bodies are placed on."""

    shape: tuple[int, int]
    resolution: float
    origin_xy: tuple[float, float]
    threads: int = 1  #: threads of the compiled loops over many items (the same answers for any)

    @property
    def corner(self) -> tuple[int, int]:
        """World cell (col, row) of the grid's cell (0, 0) (the static raster's convention)."""
        return round(self.origin_xy[0] / self.resolution), round(self.origin_xy[1] / self.resolution)


class Contact(Protocol):
    """The contact role of a kernel backend (:mod:`stage_sim.sim.backends`): where the bodies lie, which moves
    are refused. :class:`CollisionChecker` is the numpy reference, and
    :class:`~stage_sim.sim.compiled.CompiledCollisionChecker` gives its answers bit for bit."""

    def resolve(self, poses: np.ndarray, layer_poses: np.ndarray, velocities: np.ndarray, dt: float,
                moving: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One update in the layer whose robots stand at ``layer_poses``: (new poses, refused, new layer poses)."""
        ...

    def overlapping(self, poses: np.ndarray) -> np.ndarray:
        """Robots whose bodies at ``poses`` already share a cell with a static obstacle or another robot."""
        ...

    def raster(self, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(flat cell, robot) of every body cell with the robots at ``poses`` (N, 3); cell −1 off the grid."""
        ...


def decide_moves(testers, static_hit, before_start, before_other, cand_start, cand_other, back_start, back_other,
                 refused):
    """Stage's one-by-one moves: for the movers ``testers`` (ascending robot index), set ``refused[i]`` when the
    end pose hits a static cell (``static_hit[i]``) or a cell of another obstacle robot as the layer holds it
    when ``i`` moves. Per tester k, ``*_other[*_start[k]:*_start[k + 1]]`` are the robots sharing a cell with
    its end pose: at their layer pose (``before``: valid for robots not moved yet in this update), at their
    own end pose (``cand``: valid for earlier testers that moved) or back at their start pose (``back``:
    earlier testers that were refused)."""
    n = refused.size
    tester = np.zeros(n, dtype=np.bool_)
    for k in range(testers.size):
        tester[testers[k]] = True
    for k in range(testers.size):
        i = testers[k]
        hit = static_hit[i]
        if not hit:
            for m in range(before_start[k], before_start[k + 1]):
                j = before_other[m]
                if j > i or not tester[j]:
                    hit = True
                    break
        if not hit:
            for m in range(cand_start[k], cand_start[k + 1]):
                j = cand_other[m]
                if j < i and tester[j] and not refused[j]:
                    hit = True
                    break
        if not hit:
            for m in range(back_start[k], back_start[k + 1]):
                j = back_other[m]
                if j < i and tester[j] and refused[j]:
                    hit = True
                    break
        refused[i] = hit


def shared_cells(cells: np.ndarray, owner: np.ndarray, other_cells: np.ndarray, other_owner: np.ndarray,
                 robots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each robot of ``robots`` (ascending): the other robots whose cells (``other_*``) share a cell with
    its own (``cells``, ``owner``), as CSR (start per robot, robots); cells −1 ignored, repeats allowed."""
    n = np.int64(max(int(owner.max(initial=-1)), int(other_owner.max(initial=-1))) + 1)
    a = unique_sorted(cells[cells >= 0] * n + owner[cells >= 0])
    b = unique_sorted(other_cells[other_cells >= 0] * n + other_owner[other_cells >= 0])
    b_cell = b // n
    a_cell = a // n
    lo = np.searchsorted(b_cell, a_cell, side="left")
    hi = np.searchsorted(b_cell, a_cell, side="right")
    counts = hi - lo
    a_owner = np.repeat(a % n, counts)
    first = np.repeat(lo - (np.cumsum(counts) - counts), counts)
    b_owner = b[first + np.arange(counts.sum())] % n
    keep = a_owner != b_owner
    a_owner, b_owner = a_owner[keep], b_owner[keep]
    order = np.argsort(a_owner, kind="stable")
    a_owner, b_owner = a_owner[order], b_owner[order]
    # every entry's robot is one of ``robots`` (the cells given are theirs): their slices follow each other
    start = np.append(np.searchsorted(a_owner, robots, side="left"), a_owner.size).astype(np.int64)
    return start, b_owner.astype(np.int64)


RECENT_RASTERS = 3
"""Rasters of every robot a checker keeps: the ones an update asks for again (see ``_raster_of``)."""


class CollisionChecker:
    """Decides which robot moves to accept, given the static cells that block each robot's height band: the
    numpy reference of the :class:`Contact` role. The compiled backend overrides ``_integrate``, ``_raster``,
    ``_static_hits`` and ``_decide`` with the same answers."""

    def __init__(
        self, bodies: Bodies, grid: GridFrame, layers: list[TileLayer], layer_of_robot: np.ndarray,
        collides: np.ndarray,
    ) -> None:
        self.bodies = bodies
        self.grid = grid
        self._layers = layers
        self._layer_of_robot = layer_of_robot
        self.collides = collides  #: per robot: whether it stops other robots (and is tested against them)
        self.robots_can_clash = int(np.count_nonzero(collides)) > 1
        self.colliding = np.flatnonzero(collides)  #: the robots that do
        self._everyone = np.arange(bodies.count, dtype=np.int64)
        self._vertex_robot = bodies.vertex_robot
        self._next_vertex = bodies.next_vertex
        self._recent: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}
        """Rasters of every robot by the bytes of their poses, oldest first (:meth:`_raster_of`)."""

    def static_layer(self) -> TileLayer | None:
        """The static cells every robot is tested against, when all robots share one height band."""
        return self._layers[0] if len(self._layers) == 1 else None

    def resolve(self, poses: np.ndarray, layer_poses: np.ndarray, velocities: np.ndarray, dt: float,
                moving: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Move the ``moving`` robots one by one as Stage does, in the layer whose robots stand at
        ``layer_poses``; returns (new poses, refused, the layer's new poses). Robots not moving are not
        refused here: the caller keeps their stall flag, as Stage does."""
        refused = np.zeros(len(poses), dtype=bool)
        if moving.all():  # the common case, without the fancy indexing
            candidates = self._integrate(poses, velocities, dt)
            testers = self.colliding
        else:
            candidates = poses.copy()
            candidates[moving] = self._integrate(poses[moving], velocities[moving], dt)
            testers = np.flatnonzero(moving & self.collides)
        if testers.size:
            cells, owner = self._raster_of(candidates, testers)
            static_hit = self._static_hits(cells, owner)
            if self.robots_can_clash:
                others = self.colliding
                before = self._raster_of(layer_poses, others)
                back = self._raster_of(poses, testers)
                self._decide(testers, static_hit, (cells, owner), before, back, (candidates, layer_poses, poses),
                             refused)
            else:
                refused[testers] = static_hit[testers]
        final = np.where(refused[:, None], poses, candidates)
        layer = np.where(moving[:, None], final, layer_poses)
        return final, refused, layer

    def overlapping(self, poses: np.ndarray) -> np.ndarray:
        """Robots whose bodies at ``poses`` already share a cell with a static obstacle or another robot."""
        everyone = self.colliding
        touching = np.zeros(len(poses), dtype=bool)
        if not everyone.size:
            return touching
        cells, owner = self._raster(poses, everyone)
        touching |= self._static_hits(cells, owner)
        if self.robots_can_clash:
            start, _ = shared_cells(cells, owner, cells, owner, everyone)
            touching[everyone[np.diff(start) > 0]] = True
        return touching

    def raster(self, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(flat cell, robot) of every body cell with the robots at ``poses`` (N, 3); cell −1 off the grid."""
        return self._raster_of(poses, self._everyone)

    def _raster_of(self, poses: np.ndarray, robots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_raster`, remembered for the last few sets of poses of every robot: an update asks for the
        poses the layer last saw (the rays' raster of two updates ago), the start poses (last update's end
        poses) and, for the rays, the end poses it has just tested; stalled robots ask for the same ones
        again and again. The arrays are shared, never changed."""
        if robots.size != self.bodies.count:
            return self._raster(poses, robots)
        key = poses.tobytes()
        found = self._recent.get(key)
        if found is None:
            found = self._recent[key] = self._raster(poses, robots)
            if len(self._recent) > RECENT_RASTERS:
                del self._recent[next(iter(self._recent))]
        return found

    def _raster(self, poses: np.ndarray, robots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`raster` of ``robots`` (ascending) only, robot by robot, polygon by polygon, edge by edge."""
        selected = np.zeros(self.bodies.count, dtype=bool)
        selected[robots] = True
        vi = np.flatnonzero(selected[self._vertex_robot])
        position = np.empty(len(self._vertex_robot), dtype=np.int64)
        position[vi] = np.arange(vi.size)
        world = place(self.bodies.vertices[vi], poses[self._vertex_robot[vi]])
        ppm = 1.0 / self.grid.resolution
        start = np.floor(world * ppm).astype(np.int64)
        end = start[position[self._next_vertex[vi]]]
        cells, edge = edge_cells_with_edges(start, end)
        col0, row0 = self.grid.corner
        h, w = self.grid.shape
        cols, rows = cells[:, 0] - col0, cells[:, 1] - row0
        inside = (cols >= 0) & (cols < w) & (rows >= 0) & (rows < h)
        return np.where(inside, rows * w + cols, -1), self._vertex_robot[vi][edge]

    def _integrate(self, poses: np.ndarray, velocities: np.ndarray, dt: float) -> np.ndarray:
        """The end poses of one step: :func:`~stage_sim.sim.kinematics.integrate`."""
        return integrate(poses, velocities, dt)

    def _static_hits(self, cells: np.ndarray, owner: np.ndarray) -> np.ndarray:
        """Per robot: whether one of its cells (``cells``, ``owner``) is a static cell of its height band."""
        layer_index = self._layer_of_robot[owner]
        hit = np.zeros(len(cells), dtype=bool)
        for i, layer in enumerate(self._layers):
            use = (layer_index == i) & (cells >= 0)
            hit[use] = layer.contains(cells[use])
        return np.bincount(owner[hit], minlength=self.bodies.count) > 0

    def _decide(self, testers: np.ndarray, static_hit: np.ndarray, cand: tuple, before: tuple, back: tuple,
                poses: tuple, refused: np.ndarray) -> None:
        """Set ``refused`` for the ``testers`` given the rasters (cells, robot) of their end poses (``cand``),
        of the obstacle robots where the layer holds them (``before``) and of the testers' start poses
        (``back``), and the poses of those three (end, layer, start): :func:`decide_moves` on the robots
        sharing a cell. The compiled backend gets the same answers by replaying the moves one by one,
        comparing cells only between robots whose boxes meet."""
        cells, owner = cand
        decide_moves(testers, static_hit, *shared_cells(cells, owner, *before, testers),
                     *shared_cells(cells, owner, cells, owner, testers), *shared_cells(cells, owner, *back, testers),
                     refused)
