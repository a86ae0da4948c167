"""The compiled backend's roles: the numpy reference's contact, motion and laser-return code on numba kernels.

Each class or function here answers as its reference does, bit for bit (``tests/sim``); the trigonometry
stays in numpy (the kernels take the cosines and sines the reference computes). Importing this module
imports numba, so it is imported only when the numba backend is asked for
(:func:`stage_sim.sim.backends.backend_for`). Loops over many independent items run on their ``_parallel``
twin, on the grid's threads, from :data:`PARALLEL_ITEMS` items on.
"""

from __future__ import annotations

from collections.abc import Sequence
from types import ModuleType

import numpy as np

from stage_sim.backend import set_threads
from stage_sim.maps.tiles import CellValues, TileLayer
from stage_sim.sensing.robot_layer import SEVERAL_ROBOTS
from stage_sim.sim import collision_kernels, motion_kernels, ranger_kernels, sweep_kernels
from stage_sim.sim.collision import Bodies, CollisionChecker, GridFrame
from stage_sim.sim.drives import DriveGroup

# Items (points, probes, robot pairs, rays) from which a compiled loop is shared among threads.
PARALLEL_ITEMS = 4096


def kernel(module: ModuleType, name: str, items: int, threads: int):
    """The compiled kernel ``name`` of ``module``, or its ``_parallel`` twin (on ``threads`` threads) when
    there is more than one thread and more than :data:`PARALLEL_ITEMS` items to share."""
    if threads > 1 and items > PARALLEL_ITEMS:
        set_threads(threads)
        return getattr(module, name + "_parallel")
    return getattr(module, name)


class CompiledCollisionChecker(CollisionChecker):
    """:class:`~stage_sim.sim.collision.CollisionChecker` with its hooks on :mod:`stage_sim.sim.collision_kernels`
    and :mod:`stage_sim.sim.sweep_kernels`."""

    def __init__(
        self, bodies: Bodies, grid: GridFrame, layers: list[TileLayer], layer_of_robot: np.ndarray,
        collides: np.ndarray,
    ) -> None:
        super().__init__(bodies, grid, layers, layer_of_robot, collides)
        self._in_layer = [layer_of_robot == i for i in range(len(layers))]  # per layer: its robots (N,)
        # The clash test's hash table: 24 B per slot, over twice the colliding robots' points.
        points = int(self._point_count[collides].sum()) if len(collides) else 0
        size = 1 << max(1, (2 * points - 1).bit_length())
        self._table = (np.full(size, -1, dtype=np.int64), np.empty(size, dtype=np.int64),
                       np.empty(max(points, 1), dtype=np.int64))

    def _kernel(self, module: ModuleType, name: str, items: int):
        return kernel(module, name, items, self.grid.threads)

    def _body_cells(self, points: np.ndarray, pose_index: np.ndarray, poses: np.ndarray) -> np.ndarray:
        g = self.grid
        out = np.empty(len(points), dtype=np.int64)
        self._kernel(collision_kernels, "body_cells", len(points))(
            points, pose_index, poses[:, 0].copy(), poses[:, 1].copy(), np.cos(poses[:, 2]), np.sin(poses[:, 2]),
            g.resolution, *g.origin_xy, *g.shape, out)
        return out

    def _contains(self, layer: TileLayer, cells: np.ndarray) -> np.ndarray:
        out = np.empty(cells.size, dtype=bool)
        grid = layer.grid
        collision_kernels.layer_contains(cells, grid.slots, layer.tile_of_slot, layer.bits, grid.place, grid.shape[1],
                                         out)
        return out

    def _moves(
        self, poses: np.ndarray, velocities: np.ndarray, dt: float, moving: np.ndarray, movers: np.ndarray,
        refused: np.ndarray,
    ) -> np.ndarray:
        """The candidate poses and the static sweep in a handful of calls instead of some forty."""
        cos_a, sin_a = np.cos(poses[:, 2]), np.sin(poses[:, 2])
        candidates = np.empty_like(poses)
        motion_kernels.integrate_poses(poses, velocities, dt, cos_a, sin_a, candidates)
        candidates = np.where(moving[:, None], candidates, poses)
        if not movers.size:
            return candidates
        x, y, heading, robot = sweep_kernels.probe_poses(
            poses, velocities, dt, movers, np.hypot(velocities[:, 0], velocities[:, 1]), self.bodies.radius,
            self.bodies.min_width, self.grid.resolution, cos_a, sin_a)
        cos_p, sin_p = np.cos(heading), np.sin(heading)
        hit = np.zeros(len(poses), dtype=bool)
        for i, layer in enumerate(self._layers):
            grid = layer.grid
            self._kernel(sweep_kernels, "static_hits", len(x))(
                self.bodies.points, self._point_start, self._point_count, x, y, cos_p, sin_p, robot,
                self._in_layer[i], self.bodies.radius, self.grid.resolution, *self.grid.origin_xy, *self.grid.shape,
                grid.slots, grid.place, layer.tile_of_slot, layer.bits, hit)
        refused[movers] = hit[movers]
        return candidates

    def _replace_cells(self, cells: np.ndarray, poses: np.ndarray, robots: np.ndarray) -> None:
        if not robots.size:
            return
        g = self.grid
        self._kernel(collision_kernels, "robots_cells", int(self._point_count[robots].sum()))(
            self.bodies.points, self._point_start, self._point_count, robots, poses[:, 0].copy(), poses[:, 1].copy(),
            np.cos(poses[:, 2]), np.sin(poses[:, 2]), g.resolution, *g.origin_xy, *g.shape, cells)

    def _close_to_another(self, robots: np.ndarray, poses: np.ndarray) -> np.ndarray:
        close = np.zeros(robots.size, dtype=bool)
        collision_kernels.crowded(robots, poses, self.bodies.radius, 2 * self.grid.resolution, close)
        return close

    def _close_to(self, robots: np.ndarray, poses: np.ndarray) -> np.ndarray:
        near = np.zeros(self._colliding.size, dtype=bool)
        self._kernel(collision_kernels, "near_robots", robots.size * self._colliding.size)(
            self._colliding, robots, poses, self.bodies.radius, 2 * self.grid.resolution, near)
        return near

    def _clashes(self, cells: np.ndarray, among: np.ndarray) -> np.ndarray:
        conflict = np.zeros(self.bodies.count, dtype=bool)
        collision_kernels.owner_clashes(cells, among, self._point_start, self._point_count, *self._table, conflict)
        return conflict


class CompiledMotion:
    """:class:`~stage_sim.sim.backends.ReferenceMotion` in one compiled pass over the robots
    (:mod:`stage_sim.sim.motion_kernels`)."""

    @staticmethod
    def body_velocities(commands: np.ndarray, drives: Sequence[DriveGroup], wheelbases: np.ndarray, bounds: np.ndarray,
                        ) -> np.ndarray:
        steer = commands[:, 2]
        out = np.empty_like(commands)
        motion_kernels.body_velocities(commands, drives, wheelbases, bounds, np.cos(steer), np.sin(steer), out)
        return out

    @staticmethod
    def odometry(estimates: np.ndarray, velocities: np.ndarray, errors: np.ndarray, dt: float,
                 uses_odom: np.ndarray, truth: np.ndarray) -> np.ndarray:
        heading = estimates[:, 2]
        out = np.empty_like(truth)
        motion_kernels.integrate_estimates(estimates, velocities, errors, dt, np.cos(heading), np.sin(heading),
                                           uses_odom, truth, out)
        return out

    @staticmethod
    def warm(robots: int) -> None:
        motion_kernels.warm(robots)


def hit_intensity(cell: np.ndarray, hit_robot: np.ndarray, static: CellValues, robot_return: np.ndarray,
                  robots_seen: bool, rays: np.ndarray, out: np.ndarray, threads: int) -> None:
    """:func:`~stage_sim.sim.returns.hit_intensity` in one compiled pass (:mod:`stage_sim.sim.ranger_kernels`)."""
    several = float(robot_return.max(initial=0.0))
    kernel(ranger_kernels, "hit_intensity", cell.size, threads)(
        cell, hit_robot, static.cells, static.values, robot_return, robots_seen, SEVERAL_ROBOTS, several, rays, out)
