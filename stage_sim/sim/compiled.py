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
from stage_sim.maps.tiles import CellValues
from stage_sim.sensing.fast_caster import PARALLEL_RAYS
from stage_sim.sensing.robot_layer import MARKED, SEVERAL_ROBOTS
from stage_sim.sim import body_kernels, fused_kernels, motion_kernels, ranger_kernels
from stage_sim.sim.collision import CollisionChecker, Contact
from stage_sim.sim.drives import DriveGroup
from stage_sim.sim.ray_groups import SingleCast

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
    """:class:`~stage_sim.sim.collision.CollisionChecker` with its end poses, raster, static look-ups and move
    decisions on :mod:`stage_sim.sim.body_kernels` and :mod:`stage_sim.sim.motion_kernels`."""

    def _raster(self, poses: np.ndarray, robots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        g = self.grid
        b = self.bodies
        return body_kernels.body_raster(
            b.vertices, b.poly_start, b.robot_poly, robots, poses[:, 0].copy(), poses[:, 1].copy(),
            np.cos(poses[:, 2]), np.sin(poses[:, 2]), 1.0 / g.resolution, *g.corner, *g.shape)

    def _integrate(self, poses: np.ndarray, velocities: np.ndarray, dt: float) -> np.ndarray:
        out = np.empty_like(poses)
        motion_kernels.integrate_poses(poses, velocities, dt, np.cos(poses[:, 2]), np.sin(poses[:, 2]), out)
        return out

    def _static_hits(self, cells: np.ndarray, owner: np.ndarray) -> np.ndarray:
        hit = np.zeros(self.bodies.count, dtype=bool)
        for i, layer in enumerate(self._layers):
            grid = layer.grid
            body_kernels.static_hits(cells, owner, self._layer_of_robot, i, grid.slots, layer.tile_of_slot,
                                     layer.bits, grid.place, grid.shape[1], hit)
        return hit

    def _decide(self, testers: np.ndarray, static_hit: np.ndarray, cand: tuple, before: tuple, back: tuple,
                poses: tuple, refused: np.ndarray) -> None:
        candidates, layer_poses, start_poses = poses
        box = np.stack([self._boxes(p) for p in (layer_poses, candidates, start_poses)])
        body_kernels.move_one_by_one(testers, static_hit, *cand, *before, *back, self.colliding, box, refused)

    def _boxes(self, poses: np.ndarray) -> np.ndarray:
        """(col min, row min, col max, row max) world cells holding each robot's raster at ``poses``: its
        farthest vertex around the pose, a cell more on each side for the rounding."""
        ppm = 1.0 / self.grid.resolution
        reach = self.bodies.radius[:, None]
        low = np.floor((poses[:, :2] - reach) * ppm) - 1
        high = np.floor((poses[:, :2] + reach) * ppm) + 1
        return np.concatenate([low, high], axis=1).astype(np.int64)


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
    def place(points: np.ndarray, owner: np.ndarray, poses: np.ndarray) -> np.ndarray:
        out = np.empty((len(points), 2))
        motion_kernels.place_points(points, owner, poses, np.cos(poses[:, 2]), np.sin(poses[:, 2]), out)
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


class FusedStep:
    """A whole step of a world on the compiled kernels in two calls (:mod:`stage_sim.sim.fused_kernels`): the
    moves, contacts and odometry, then every ray; the numpy calls left are the trigonometry's and the new
    arrays'. For worlds whose robots share one height band and whose rays one height, without noise and on
    one thread (:meth:`of`); other worlds, and steps when only some rangers are due, step role by role."""

    def __init__(self, collision: CompiledCollisionChecker, cast: SingleCast) -> None:
        bodies, grid = collision.bodies, collision.grid
        layer = collision.static_layer()
        self._collision = collision
        self._cast = cast
        self._bodies = (bodies.vertices, bodies.poly_start, bodies.robot_poly)
        self._radius = bodies.radius
        self._grid = np.array([*grid.corner, *grid.shape], dtype=np.int64)
        self._ppm = 1.0 / grid.resolution
        self._static = (layer.grid.slots, layer.tile_of_slot, layer.bits, layer.grid.place)
        group = cast.group
        self._robots = group.robots
        self._region_place = group.robots.grid.place
        self._walk = group.caster.walk_arguments(cast.longest)
        self._robots_seen = bodies.count > 1  # a lone robot never sees itself
        self._several_return = float(group.robot_return.max(initial=0.0))
        beams = group.rays.size
        self._ranges = np.empty(beams)
        self._cell = np.empty(beams, dtype=np.int64)
        self._hit_robot = np.empty(beams, dtype=np.int32)
        self._integrated = np.empty((bodies.count, 3))

    @classmethod
    def of(cls, collision: Contact, cast: SingleCast | None, threads: int) -> FusedStep | None:
        """The fused step of a world's compiled contacts and rays (None: not all at one height, or noisy), or None
        when it steps role by role: robots in several height bands, or more than one thread with more rays than
        a cast keeps on one (the parallel loops)."""
        if (cast is None or not isinstance(collision, CompiledCollisionChecker) or collision.static_layer() is None
                or (threads > 1 and cast.group.rays.size > PARALLEL_RAYS)):
            return None
        return cls(collision, cast)

    def step(self, poses: np.ndarray, layer_poses: np.ndarray, velocities: np.ndarray, stalled: np.ndarray,
             estimates: np.ndarray, errors: np.ndarray, uses_odom: np.ndarray, dt: float,
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """One step from ``poses`` in the layer at ``layer_poses`` with ``velocities``, every ray cast: (new poses,
        stall flags, odometry, layer poses, float32 ranges and intensities of every beam), new arrays."""
        n = poses.shape[0]
        start_trig = _trig(poses)
        motion_kernels.integrate_poses(poses, velocities, dt, start_trig[0], start_trig[1], self._integrated)
        final, layer_out, odometry = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
        stalled_out = np.empty(n, dtype=bool)
        final_trig = np.empty((2, n))
        collision = self._collision
        cells, cell_robot = fused_kernels.move(
            poses, self._integrated, layer_poses, velocities, stalled, estimates, errors, dt, uses_odom, start_trig,
            _trig(self._integrated), _trig(layer_poses), _trig(estimates), self._bodies, self._radius, self._grid,
            self._ppm, collision.collides, collision.colliding, collision.robots_can_clash, self._static, final,
            stalled_out, layer_out, odometry, final_trig)
        published, intensity = self._sense(final, final_trig, cells, cell_robot)
        return final, stalled_out, odometry, layer_out, published, intensity

    def _sense(self, poses: np.ndarray, trig: np.ndarray, cells: np.ndarray, cell_robot: np.ndarray,
               ) -> tuple[np.ndarray, np.ndarray]:
        """Every ray cast from ``poses`` (cos and sin ``trig``) with the robots' raster (``cells``, ``cell_robot``):
        (float32 ranges, intensities)."""
        cast, robots = self._cast, self._robots
        group = cast.group
        published = np.empty(group.rays.size, dtype=np.float32)
        intensity = np.empty(group.rays.size, dtype=np.float32)
        world, place, stops, pad, ppm = self._walk
        while True:
            layer = (robots.regions, robots.ids, robots.rows, robots.cols, robots.rows_used, robots.cols_used,
                     robots.owner)
            marked, count, active = fused_kernels.sense(
                poses, trig, cast.ranger_offset, cast.ranger_owner, cells, cell_robot, self._robots_seen,
                group.robot_visible, layer, robots.marked, robots.active, robots.capacity, self._region_place,
                robots.shape[1], MARKED, SEVERAL_ROBOTS, world, place, stops, pad, group.ranger, group.angle,
                group.max_range, group.owner, group.rays, cast.no_jitter, cast.trig, ppm, group.intensity.cells,
                group.intensity.values, group.robot_return, self._several_return, self._ranges, self._cell,
                self._hit_robot, published, intensity)
            robots.took(marked, active)
            if count <= robots.capacity:
                return published, intensity
            robots.reserve(count)


def _trig(poses: np.ndarray) -> np.ndarray:
    """(2, N): numpy's cos and sin of the headings ``poses[:, 2]``, the calls the role-by-role kernels make."""
    heading = poses[:, 2]
    trig = np.empty((2, heading.size))
    np.cos(heading, out=trig[0])
    np.sin(heading, out=trig[1])
    return trig
