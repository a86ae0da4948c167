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
from stage_sim.sensing.robot_layer import SEVERAL_ROBOTS
from stage_sim.sim import body_kernels, motion_kernels, ranger_kernels
from stage_sim.sim.collision import CollisionChecker
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
        body_kernels.move_one_by_one(testers, static_hit, *cand, *before, *back, self._colliding, box, refused)

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
