"""The compiled backend's roles: the numpy reference's contact, motion and laser-return code on numba kernels.

Each class or function here answers as its reference does, bit for bit (``tests/sim``); the trigonometry
stays in numpy (the kernels take the cosines and sines the reference computes). Importing this module
imports numba, so it is imported only when the numba backend is asked for
(:func:`stage_sim.sim.backends.backend_for`). Loops over many independent items run on their ``_parallel``
twin, on the grid's threads, from :data:`PARALLEL_ITEMS` items on.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType

import numpy as np
from numba import typed

from stage_sim.backend import set_threads
from stage_sim.maps.tiles import CellValues
from stage_sim.sensing.fast_caster import PARALLEL_RAYS
from stage_sim.sensing.robot_layer import MARKED, SEVERAL_ROBOTS
from stage_sim.sim import body_kernels, fused_kernels, motion_kernels, ranger_kernels
from stage_sim.sim.collision import CollisionChecker, Contact
from stage_sim.sim.drives import DriveGroups, DriveTable
from stage_sim.sim.ray_groups import SingleCast

#: The steering cos and sin given to drives that read none (``Drive.steered``).
_UNSTEERED = np.zeros(0)
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
    def body_velocities(commands: np.ndarray, drives: DriveGroups, wheelbases: np.ndarray, bounds: np.ndarray,
                        ) -> np.ndarray:
        out = np.empty_like(commands)
        cos_steer = sin_steer = _UNSTEERED
        if drives.steered:
            steer = commands[:, 2]
            cos_steer, sin_steer = np.cos(steer), np.sin(steer)
        motion_kernels.body_velocities(commands, drives, wheelbases, bounds, cos_steer, sin_steer, out)
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


@dataclass(slots=True)
class FusedResult:
    """A fused step's new state (new arrays) and scans (not frozen: made every step, a frozen one sets each field
    through ``object.__setattr__``)."""

    poses: np.ndarray
    stalled: np.ndarray
    odometry: np.ndarray
    layers: np.ndarray  #: (2, N, 3) the robots' poses in each of Stage's layers
    scans: tuple[np.ndarray, np.ndarray] | None  #: float32 ranges and intensities of every beam (None: no cast)
    velocities: np.ndarray  #: (N, 3) the body velocities the robots moved with
    grown: bool = False  #: whether the rays were cast again after the step's call, into a robot layer grown for them


class FusedStep:
    """A whole step of a world on the compiled kernels in one call (:mod:`stage_sim.sim.fused_kernels`): the
    end poses and odometry, the contacts and every ray; the numpy calls left are the noise's draws and the new
    arrays. For worlds whose robots share one height band and whose rays one
    height, on one thread (:meth:`of`); other worlds, and steps when only some rangers are due, step role by
    role."""

    def __init__(self, collision: CompiledCollisionChecker, cast: SingleCast, drives: DriveTable) -> None:
        bodies, grid = collision.bodies, collision.grid
        static = collision.static_layer()
        group = cast.group
        n, beams = bodies.count, group.rays.size
        world, place, stops, pad, walk_ppm = group.caster.walk_arguments(cast.longest)
        self._robots = group.robots
        self._fields = {
            "vertices": bodies.vertices, "poly_start": bodies.poly_start, "robot_poly": bodies.robot_poly,
            "radius": bodies.radius, "grid": np.array([*grid.corner, *grid.shape, static.grid.shape[1]]),
            "ppm": 1.0 / grid.resolution, "collides": collision.collides, "colliding": collision.colliding,
            "can_clash": collision.robots_can_clash, "slots": static.grid.slots, "tile_of_slot": static.tile_of_slot,
            "bits": static.bits, "static_place": static.grid.place, "ranger_offset": cast.ranger_offset,
            "ranger_owner": cast.ranger_owner, "robots_seen": n > 1,  # a lone robot never sees itself
            "visible": group.robot_visible, "region_place": group.robots.grid.place, "width": group.robots.shape[1],
            "marked_value": MARKED, "several": SEVERAL_ROBOTS, "walk_place": place, "stops": stops, "pad": pad,
            "walk_ppm": walk_ppm, "ranger": group.ranger, "angle": group.angle, "rmax": group.max_range,
            "owner": group.owner, "rays": group.rays, "jitter": cast.jitter, "noisy_rays": cast.noisy_rays,
            "noise_prop": cast.noise_prop, "noise_uniform": cast.noise_uniform, "noise_gauss": cast.noise_gauss,
            "static_cells": group.intensity.cells,
            "static_values": group.intensity.values, "robot_return": group.robot_return,
            "several_return": float(group.robot_return.max(initial=0.0)), "ranges": np.empty(beams),
            "cell": np.empty(beams, dtype=np.int64), "hit_robot": np.empty(beams, dtype=np.int32),
            "headings": np.zeros((2 * n, 3)),  # column 2: a step's new headings (end poses, then odometry) ...
            "known": np.full((4, n), np.nan),  # ... the headings of the poses, odometry, layers 0 and 1 ...
            "known_trig": np.empty((4, 2, n)),  # ... and their cos and sin
            # the last cast through each layer, kept for the steps whose robots stand still (shared by every pack)
            "cast_keys": np.empty((2, 2, n, 3)), "cast_ranges": np.empty((2, beams)),
            "cast_intensity": np.empty((2, beams), dtype=np.float32), "cast_state": np.zeros((2, 2), dtype=np.int64),
            "replays": np.zeros(1, dtype=np.int64), "drive_rows": motion_kernels.drive_rows(drives.groups),
            "wheelbases": drives.wheelbases, "bounds": drives.bounds,
            **dict(zip(("walk_rows", "walk_cols", "walk_tiles", "walk_slots", "walk_rows_used", "walk_cols_used"),
                       world, strict=True)),
            **dict(zip(("last_angle", "last_cos", "last_sin"), cast.trig, strict=True)),
        }
        self._beams = beams
        # scratch: the end poses, the cos and sin of the new headings and those of the new poses
        self._scratch = (np.empty((n, 3)), np.empty((2, 2 * n)), np.empty((2, n)))
        self._pack()

    def _pack(self) -> None:
        """The fields in one argument, with the robot layer's tables as they stand (they grow, rarely; the
        sensing's own casts may grow them too)."""
        robots = self._robots
        self._ids = robots.ids
        tables = dict(zip(("regions", "ids", "rows", "cols", "rows_used", "cols_used", "tile_owner"), robots.tables,
                          strict=True))
        fields = {**self._fields, **tables, "capacity": robots.capacity, "marked": robots.marked_regions,
                  "marked_count": robots.marked_count, "active": robots.active_flag}
        self._world = fused_kernels.fused_world(*(fields[name] for name in fused_kernels.FIELDS))

    @classmethod
    def of(cls, collision: Contact, cast: SingleCast | None, threads: int, drives: DriveTable) -> FusedStep | None:
        """The fused step of a world's compiled contacts and rays (``cast`` None: not all at one height, or no
        robot) and its robots' ``drives``, or None when it steps role by role: robots in several height bands, or
        more than one thread with more rays than a cast keeps on one (the parallel loops)."""
        if (cast is None or not isinstance(collision, CompiledCollisionChecker) or collision.static_layer() is None
                or (threads > 1 and cast.group.rays.size > PARALLEL_RAYS)):
            return None
        return cls(collision, cast, drives)

    def step(self, commands: np.ndarray, poses: np.ndarray, layers: np.ndarray, layer: int, stalled: np.ndarray,
             estimates: np.ndarray, errors: np.ndarray, uses_odom: np.ndarray, dt: float, cast: bool,
             kernel: Callable[..., int] | None = None, arguments: tuple = ()) -> FusedResult:
        """One step from ``poses`` in layer ``layer`` of ``layers`` (2, N, 3) with the body velocities of
        ``commands``; every ray cast when ``cast``, none else (no ranger due).

        ``kernel``: a compiled function called instead of :func:`~stage_sim.sim.fused_kernels.commanded_step` with
        its arguments, then ``arguments``, which calls it and returns its answer (an RL task's step: commands
        written before, observations after, in the same call)."""
        world = self.world()
        n, (integrated, end_trig, final_trig) = poses.shape[0], self._scratch
        velocities, odometry, final, stalled_out = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)), \
            np.empty(n, dtype=bool)
        layers = layers.copy()
        published, intensity = np.empty(self._beams, dtype=np.float32), np.empty(self._beams, dtype=np.float32)
        tiles = (kernel or fused_kernels.commanded_step)(
            world, commands, velocities, poses, layers, layer, estimates, errors, dt, uses_odom, stalled, cast,
            integrated, end_trig, final_trig, odometry, final, stalled_out, published, intensity, *arguments)
        if not cast:
            return FusedResult(final, stalled_out, odometry, layers, None, velocities)
        grown = tiles > self._robots.capacity
        if grown:  # the layer grows (rarely: it never shrinks), and the rays are cast with it
            self.cast_grown(tiles, layers, layer, final, final_trig, published, intensity)
        return FusedResult(final, stalled_out, odometry, layers, (published, intensity), velocities, grown)

    @property
    def beams(self) -> int:
        """Rays its steps cast."""
        return self._beams

    @property
    def replayed_casts(self) -> int:
        """Casts answered by the kept one, its robots having stood still since
        (:func:`~stage_sim.sim.fused_kernels._cast_kept`)."""
        return int(self._fields["replays"][0])

    def world(self) -> fused_kernels.FusedWorld:
        """What its kernels read besides the robots' state, with the robot layer's tables as they stand."""
        if self._robots.ids is not self._ids:
            self._pack()
        return self._world

    def cast_grown(self, tiles: int, layers: np.ndarray, layer: int, poses: np.ndarray, trig: np.ndarray,
                   published: np.ndarray, intensity: np.ndarray) -> None:
        """Grow the robot layer to ``tiles`` and cast every ray again
        (:func:`~stage_sim.sim.fused_kernels.sense_again`), after a step found it too small."""
        self._robots.reserve(tiles)
        self._pack()
        fused_kernels.sense_again(self._world, layers, layer, poses, trig, published, intensity)

    def warm(self, poses: np.ndarray) -> None:
        """Load its kernels (compiling what numba's cache lacks): a step from ``poses``, a cast into a grown
        robot layer, then a cast through no robot cell, which leaves the layer empty; the results are dropped
        (what it remembers is checked at every step)."""
        n = len(poses)
        layers = np.stack([poses, poses])
        self.step(np.full_like(poses, 1e-3), poses, layers, 0, np.zeros(n, dtype=bool), poses, np.zeros((n, 4)),
                  np.ones(n, dtype=bool), 0.1, True)
        final_trig = self._scratch[2]
        fused_kernels.sense_again(self._world, layers, 0, poses, final_trig, np.empty(self._beams, dtype=np.float32),
                                  np.empty(self._beams, dtype=np.float32))
        fused_kernels.sense(self._world, poses, final_trig, np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
                            np.empty(self._beams, dtype=np.float32), np.empty(self._beams, dtype=np.float32), 0)


class FusedBatch:
    """The fused steps of several worlds of one shape (the worlds of a vector env) in one compiled call
    (:func:`~stage_sim.sim.fused_kernels.whole_steps`, or its parallel twin on more than one thread), every ray
    cast: one dispatch and one check of the arguments for all of them. Each world's step is held in its slot
    (:meth:`hold`) and its :class:`FusedWorld` stays in a typed list between calls, written again only when the
    world changes (a new step held in the slot, a grown robot layer)."""

    def __init__(self, threads: int) -> None:
        """``threads``: the worlds are shared among that many threads (the same answers)."""
        self._threads = threads
        self._worlds: typed.List | None = None
        self._steps: list[FusedStep] = []  # the step held in each slot
        self._type: object = None  # numba's type of the worlds (numba's types are interned: one object per type)
        self.beams = -1  #: rays every world's step casts (those of the first asked)

    def fits(self, fused: FusedStep) -> bool:
        """Whether ``fused`` can join the others' call: the same rays and the same kinds of arrays as the first
        that was asked."""
        world_type = fused.world()._numba_type_
        if self._type is None:
            self._type, self.beams = world_type, fused.beams
        return fused.beams == self.beams and world_type is self._type

    def hold(self, slot: int, fused: FusedStep) -> None:
        """Step ``fused`` (which :meth:`fits`) in ``slot`` from now on."""
        if self._worlds is None:
            self._worlds = typed.List.empty_list(self._type)
        world = fused.world()
        while len(self._steps) <= slot:
            self._steps.append(fused)
            self._worlds.append(world)
        self._steps[slot] = fused
        self._worlds[slot] = world

    def step(self, slots: np.ndarray, poses: np.ndarray, layers: np.ndarray, parity: np.ndarray,
             estimates: np.ndarray, velocities: np.ndarray, errors: np.ndarray, dt: float, uses_odom: np.ndarray,
             stalled: np.ndarray) -> FusedResult:
        """The step held in each of ``slots`` (every ray cast), on the slot's row of the state (a row per slot:
        ``poses`` (W, N, 3), ``layers`` (W, 2, N, 3) written in place, its layer ``parity[slot]``, ...): new arrays
        of a row per slot, the stepped slots' rows written (the others' as given; their scans unset); the scans
        (W, beams)."""
        worlds = self._worlds
        size, n = poses.shape[:2]
        beams = self.beams
        integrated, end_trig, final_trig = np.empty((size, n, 3)), np.empty((size, 2, 2 * n)), np.empty((size, 2, n))
        odometry, final, stalled_out = estimates.copy(), poses.copy(), stalled.copy()  # the others' rows: as they were
        published, intensity = np.empty((size, beams), dtype=np.float32), np.empty((size, beams), dtype=np.float32)
        tiles = np.zeros(size, dtype=np.int64)
        step_all = fused_kernels.whole_steps
        if self._threads > 1 and slots.size > 1:  # the worlds shared among the threads
            set_threads(self._threads)
            step_all = fused_kernels.whole_steps_parallel
        step_all(worlds, slots, poses, layers, parity, estimates, velocities, errors, dt, uses_odom, stalled,
                 integrated, end_trig, final_trig, odometry, final, stalled_out, published, intensity, tiles)
        for slot in np.flatnonzero(tiles).tolist():  # a robot layer too small: grown, its rays cast again
            fused = self._steps[slot]
            fused.cast_grown(int(tiles[slot]), layers[slot], int(parity[slot]), final[slot], final_trig[slot],
                             published[slot], intensity[slot])
            worlds[slot] = fused.world()
        return FusedResult(final, stalled_out, odometry, layers, (published, intensity), velocities)
