"""Lasers: every due beam of every ranger of every robot cast in one batch per height, then Stage's noise.

Rays are grouped by height because of Stage's 2.5D rule (a ray sees a model only if its height lies in the
model's z band); worlds have one or two distinct laser heights, each with its own precomputed static
layer. Other robots are seen through their outline cells, placed fresh at every sensing step; a ray never
sees its own robot. A ranger produces a new scan when ``update_interval`` has passed since its last one.

Noise (``noise [c p a]``, Stage 4.3): each beam's direction is perturbed by inc·a·U/2 and a hit's range
becomes r + r·p·U' + G, with U, U' uniform in [−1, 1) and G normal with variance c; misses stay at
``range_max``. The draws come from the simulation's seeded generator, so a seed fixes every scan.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from stage_sim.maps.raster import StaticRaster
from stage_sim.sensing.casters import RayCaster
from stage_sim.sim.collision import Bodies, GridFrame
from stage_sim.sim.ray_groups import HeightGroup, SingleCast
from stage_sim.sim.robots import RobotSpec

if TYPE_CHECKING:
    from stage_sim.sim.backends import Backend


@dataclass
class Scan:
    """One ranger's latest measurement: ranges (m) and intensities per beam, CCW, and its sim stamp (s)."""

    ranges: np.ndarray
    intensities: np.ndarray
    stamp: float


class MeasuredBeams(NamedTuple):
    """Every beam the last sensing cast, all rangers' end to end in robot and ranger order (the scans are views
    of these): a recording copies a step's scans in one piece. A named tuple: made every step, and a frozen
    dataclass costs a microsecond to make."""

    time: float
    """The sim time of that sensing (s): the scans' stamp."""
    ranges: np.ndarray
    """float32, a value per beam of every ranger; those of rangers not due hold nothing."""
    intensities: np.ndarray
    due: np.ndarray | None
    """Which rangers measured (bool per ranger), None: all of them."""
    ray_due: np.ndarray | None
    """The same per beam."""


@dataclass(frozen=True)
class _BeamTable:
    """The rays of one height and what they read of their rangers and robots (:class:`HeightGroup`'s fields that
    do not depend on the static world)."""

    height: float
    rays: np.ndarray
    owner: np.ndarray
    ranger: np.ndarray
    angle: np.ndarray
    max_range: np.ndarray
    visible: np.ndarray
    """Per robot: whether rays at this height see it."""
    returns: np.ndarray
    """Per robot: its ``ranger_return``."""


class RangerSensing:
    """Holds the beam tables of all rangers and produces their scans."""

    def __init__(
        self, robots: list[RobotSpec], static: StaticRaster, bodies: Bodies, grid: GridFrame, backend: Backend,
        raster: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
    ) -> None:
        """``backend``: the kernels the rays are cast and their returns looked up with; ``raster``: the
        cells of the robots' bodies at given poses (:meth:`~stage_sim.sim.collision.Contact.raster`)."""
        self._bodies = bodies
        self._grid = grid
        self._backend = backend
        self._raster = raster
        self._rangers = [(robot.index, ranger) for robot in robots for ranger in robot.rangers]
        owners, angles, ranges, heights, ranger_of_ray = [], [], [], [], []
        for k, (robot_index, ranger) in enumerate(self._rangers):
            beams = ranger.beam_angles
            owners.append(np.full(len(beams), robot_index))
            angles.append(ranger.ray_yaw + beams)
            ranges.append(np.full(len(beams), ranger.sensor.range_max))
            heights.append(np.full(len(beams), ranger.ray_height))
            ranger_of_ray.append(np.full(len(beams), k))
        self._owner = np.concatenate(owners).astype(np.int64) if owners else np.zeros(0, np.int64)
        # Every beam of a ranger starts at the same point: placed once per ranger, not once per beam.
        self._ranger_offset = np.array([r.ray_offset for _, r in self._rangers], dtype=np.float64).reshape(-1, 2)
        self._ranger_owner = np.array([i for i, _ in self._rangers], dtype=np.int64)
        self._angle = np.concatenate(angles) if angles else np.zeros(0)
        self._max_range = np.concatenate(ranges) if ranges else np.zeros(0)
        self._ranger_of_ray = np.concatenate(ranger_of_ray).astype(np.int64) if ranger_of_ray else np.zeros(0, int)
        self._increment = np.array([r.sensor.fov / max(r.sensor.samples - 1, 1) for _, r in self._rangers])
        self._noise = np.array([r.sensor.noise for _, r in self._rangers]).reshape(-1, 3)
        self._interval_us = np.array([round(r.update_interval * 1e6) for _, r in self._rangers], dtype=np.int64)
        self._ray_noise = self._noise[self._ranger_of_ray]
        self._noisy = bool(np.any(self._noise != 0.0))
        self._angle_noisy = bool(np.any(self._noise[:, 2] != 0.0))
        self._robots = robots
        self._ray_height = np.concatenate(heights) if heights else np.zeros(0)
        self._beam_tables = self._tables_by_height(robots)
        self._static = static
        self._casters: dict[tuple[str, int, int], RayCaster] = {}
        """The casters of ``_static``'s layers by kernels, threads and layer (its id), shared by every sensing
        over that raster (:meth:`over`)."""
        self._groups = self._height_groups()
        self._slices = self._ranger_slices()
        self._scan_slots = [(robot_index, ranger.index, part)
                            for (robot_index, ranger), part in zip(self._rangers, self._slices, strict=True)]
        self._beam_slices = {(robot_index, ranger_index): part for robot_index, ranger_index, part in self._scan_slots}
        """:meth:`beams_of` of every ranger (an env reads its robots' every step)."""
        self._no_jitter = np.zeros(0)
        self._longest_us = int(self._interval_us.max(initial=0))
        self._shortest_us = int(self._interval_us.min(initial=0))
        self._every_ray = np.ones(len(self._owner), dtype=bool)
        self._start()

    def over(self, static: StaticRaster, grid: GridFrame, backend: Backend,
             raster: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]) -> RangerSensing:
        """These rangers over a static world (an episode's obstacles added: an env's reset; or this very one: a
        vector env's worlds of one world file), on ``backend``: what a new RangerSensing of the same robots gives,
        the beam tables shared (they depend on the robots alone), the casters too when ``static`` is this sensing's
        own raster (a caster holds nothing a cast changes: each world keeps its own robot layer), else made for
        ``static``, and everything a cast changes fresh."""
        sensing = copy.copy(self)
        sensing._grid, sensing._backend, sensing._raster = grid, backend, raster
        sensing._static, sensing._casters = static, self._casters if static is self._static else {}
        sensing._groups = sensing._height_groups()
        sensing._start()
        return sensing

    def _start(self) -> None:
        """What casts change, as before the first: no scans, every ranger due, trigonometry and noise buffers
        unset, a fresh generator."""
        # every beam's last angle with its cos and sin (24 B a beam), which the compiled caster keeps: a robot
        # that did not turn (a stalled one) does not compute them again
        self._trig = tuple(np.full(len(self._owner), np.nan) for _ in range(3))
        self._all_cast = self._all_cast_noise()
        self._latest: list[list[Scan]] = [[] for _ in self._robots]
        self._unpublished: tuple[np.ndarray, np.ndarray, float] | None = None
        """A fused step's cast of every ranger (float32 ranges, intensities, time) not made into scans yet."""
        self._unmeasured: tuple[np.ndarray, np.ndarray, float] | None = None
        """The same cast, not made into :attr:`measured` yet."""
        self._measured: MeasuredBeams | None = None
        self._rng = np.random.default_rng()
        self._last_us = np.zeros(len(self._rangers), dtype=np.int64)
        self._all_cast_us: int | None = None
        """When the last cast of every ranger was, while ``_last_us`` does not hold it yet (:meth:`_last_casts`)."""
        self._all_due_us = 0
        """From this sim time on every ranger is due (the common step, told without an array per ranger)."""
        self._next_due_us = 0
        """Before this sim time no ranger is due (the steps between a slow laser's scans)."""
        self._stale = True

    def reset(self, rng: np.random.Generator) -> None:
        """Use ``rng`` for the noise from now on."""
        self._rng = rng

    def adopt(self, previous: RangerSensing) -> None:
        """Carry on where ``previous`` (the same rangers on other kernels) stands: its latest scans, schedule,
        pending re-scan and random generator."""
        self._latest = previous.latest
        self._measured, self._unmeasured = previous.measured, None
        self._last_us = previous._last_casts().copy()
        self._all_cast_us = None
        self._all_due_us = previous._all_due_us
        self._next_due_us = previous._next_due_us
        self._stale = previous._stale
        self._rng = previous._rng

    @property
    def measured(self) -> MeasuredBeams | None:
        """The beams of the last sensing that cast any (None before the first); those of a fused step's cast are
        wrapped when first read (a run that reads none, an env's, wraps none)."""
        if self._unmeasured is not None:
            published, intensity, time = self._unmeasured
            self._unmeasured = None
            self._measured = MeasuredBeams(time, published, intensity, None, None)
        return self._measured

    def _last_casts(self) -> np.ndarray:
        """When each ranger last cast (µs), brought up to date after the casts of every ranger."""
        if self._all_cast_us is not None:
            self._last_us.fill(self._all_cast_us)  # a slice assignment costs twice as much
            self._all_cast_us = None
        return self._last_us

    @property
    def latest(self) -> list[list[Scan]]:
        """The latest scan of every ranger, per robot; those of a fused step's cast are made when first read: a
        run that reads no scans (a vector env, a benchmark, a bag, which keeps :attr:`measured`) makes none
        (about 1.5 µs a step for one robot)."""
        if self._unpublished is not None:
            published, intensity, time = self._unpublished
            self._unpublished = None
            self._publish(range(len(self._rangers)), published, intensity, time)
        return self._latest

    def invalidate(self) -> None:
        """Make every ranger due at the next :meth:`sense` (after a reset: cheap, however often it comes)."""
        self._stale = True

    def sense(self, poses: np.ndarray, time: float,
              body_cells: tuple[np.ndarray, np.ndarray] | None = None) -> None:
        """Cast the rangers that are due at ``time`` (all of them after :meth:`invalidate`) from ``poses``;
        ``body_cells``: the robots' raster the rays see, (cell, robot)
        (:meth:`~stage_sim.sim.collision.Contact.raster`), when the caller has it (else the bodies at ``poses``)."""
        now_us = round(time * 1e6)
        if self.all_due(now_us):
            due = None
            self._mark_all_cast(now_us)
        else:
            self._stale = False
            due = (now_us - self._last_casts()) >= self._interval_us
            if not due.any():
                return
            self._last_us[due] = now_us
            self._all_due_us = int((self._last_us + self._interval_us).max())
            self._next_due_us = int((self._last_us + self._interval_us).min())
        ray_due = None if due is None else due[self._ranger_of_ray]
        ranges = np.zeros(len(self._owner))  # rays not due keep 0, never garbage that overflows float32
        intensity = np.zeros(len(self._owner), dtype=np.float32)
        # Even a lone robot's cells count: they make Stage's regions around it non-empty (sensing/stage_walk.py).
        robot_cells = None
        if self._bodies.count:
            robot_cells = self._raster(poses) if body_cells is None else body_cells
        jitter = self._angle_jitter(ray_due) if self._angle_noisy else None
        origins = self._backend.motion.place(self._ranger_offset, self._ranger_owner, poses)
        for group in self._groups:
            chosen = None if ray_due is None else np.flatnonzero(ray_due[group.rays])
            if chosen is None or chosen.size:
                self._cast(group, chosen, poses, origins, jitter, robot_cells, ranges, intensity)
        noisy = self._apply_noise(ranges, self._every_ray if ray_due is None else ray_due) \
            if self._noisy else ranges
        published = noisy.astype(np.float32)  # one conversion; each scan holds views of its own beams
        self._publish(range(len(self._rangers)) if due is None else np.flatnonzero(due), published, intensity, time)
        self._measured, self._unmeasured = MeasuredBeams(time, published, intensity, due, ray_due), None

    def beams_of(self, robot: int, ranger: int) -> slice:
        """Where the beams of ranger ``ranger`` of robot ``robot`` lie among every ranger's
        (:attr:`~stage_sim.sim.simulation.Simulation.measured_beams`)."""
        try:
            return self._beam_slices[robot, ranger]
        except KeyError:
            raise IndexError(f"robot {robot} has no ranger {ranger}") from None

    def all_due(self, now_us: int) -> bool:
        """Whether every ranger is due at sim time ``now_us`` (µs; the common step; always after
        :meth:`invalidate`)."""
        return self._stale or now_us >= self._all_due_us

    def due_every_step(self, now_us: int, interval_us: int) -> bool:
        """Whether every ranger is due at sim time ``now_us`` and, cast then, at every ``interval_us`` after: none
        updates more slowly than the step (what a :class:`~stage_sim.sim.simulation.SimulationBatch` holds)."""
        return self.all_due(now_us) and self._longest_us <= interval_us

    @property
    def noisy(self) -> bool:
        """Whether a cast draws noise (:meth:`draw_all_noise` before a fused step's)."""
        return self._noisy

    def none_due(self, now_us: int) -> bool:
        """Whether no ranger is due at sim time ``now_us`` (µs; :meth:`sense` would cast nothing)."""
        return not self._stale and now_us < self._next_due_us

    def single_cast(self) -> SingleCast | None:
        """What a fused step (:class:`~stage_sim.sim.compiled.FusedStep`) needs to cast every ray in one call, when
        it can: all rays at one height, a robot at least; else None (:meth:`sense` casts them)."""
        if len(self._groups) != 1 or not self._bodies.count:
            return None
        jitter, _, _, noisy_rays, prop, _, uniform, gauss = self._all_cast
        return SingleCast(self._groups[0], self._ranger_offset, self._ranger_owner, self._trig,
                          float(self._max_range.max(initial=0.0)), jitter, noisy_rays, prop, uniform, gauss)

    def draw_all_noise(self) -> None:
        """Draw the noise of a cast of every ray into :meth:`single_cast`'s buffers, before a fused step casts
        them: the draws :meth:`sense` makes for it, in its order (directions, then U', then G)."""
        if not self._noisy:
            return
        jitter, jitter_rays, jitter_scale, noisy_rays, _, sqrt_const, uniform, gauss = self._all_cast
        if jitter_rays.size:
            jitter[jitter_rays] = jitter_scale * self._rng.uniform(-1.0, 1.0, len(jitter_rays))
        if noisy_rays.size:
            uniform[:] = self._rng.uniform(-1.0, 1.0, len(noisy_rays))
            gauss[:] = self._rng.normal(0.0, 1.0, len(noisy_rays)) * sqrt_const

    def record_all(self, published: np.ndarray, intensity: np.ndarray, now_us: int) -> None:
        """Take the scans of every ranger cast at sim time ``now_us`` (µs) by a fused step (when :meth:`all_due`):
        what :meth:`sense` keeps of its own cast."""
        self._mark_all_cast(now_us)
        self._unpublished = self._unmeasured = published, intensity, now_us / 1e6

    def _mark_all_cast(self, now_us: int) -> None:
        """Every ranger cast at ``now_us``: the next all-due step is a longest interval away."""
        self._stale = False
        self._all_cast_us = now_us  # written into the last casts when they are read
        self._all_due_us = now_us + self._longest_us
        self._next_due_us = now_us + self._shortest_us

    def _publish(self, rangers: Iterable[int], published: np.ndarray, intensity: np.ndarray, time: float) -> None:
        """New scans of ``rangers`` from the float32 ranges and intensities of all beams (views of their own)."""
        latest = self.latest  # after the scans of a cast not made into scans yet
        for k in rangers:
            robot_index, ranger_index, part = self._scan_slots[k]
            scan = Scan(published[part], intensity[part], time)
            robot_scans = latest[robot_index]
            if ranger_index < len(robot_scans):
                robot_scans[ranger_index] = scan
            else:
                robot_scans.append(scan)

    def _cast(
        self, group: HeightGroup, chosen: np.ndarray | None, poses: np.ndarray, origins: np.ndarray,
        jitter: np.ndarray | None, robot_cells: tuple[np.ndarray, np.ndarray] | None, ranges: np.ndarray,
        intensity: np.ndarray,
    ) -> None:
        """Cast the group's rays (those at ``chosen`` positions of it; all when None) from the rangers'
        ``origins`` and write their ranges and intensities."""
        owner, ranger, angle, max_range, rays = group.owner, group.ranger, group.angle, group.max_range, group.rays
        if chosen is not None:
            owner, ranger, angle, max_range, rays = (
                owner[chosen], ranger[chosen], angle[chosen], max_range[chosen], rays[chosen])
        layer = None
        if robot_cells is not None:
            if self._bodies.count > 1:
                group.robots.update_flat(*robot_cells, group.robot_visible)
            else:  # a lone robot never sees itself, but its cells make Stage's regions around it non-empty
                group.robots.mark_flat(robot_cells[0])
            layer = group.robots
        cell, hit_robot = group.caster.cast_into(
            origins, ranger, poses[self._ranger_owner, 2], angle, max_range, owner, layer, rays, ranges,
            jitter=self._no_jitter if jitter is None else jitter, trig=self._trig)
        # a lone robot never sees itself
        self._backend.hit_intensity(cell, hit_robot, group.intensity, group.robot_return, self._bodies.count > 1,
                                    rays, intensity, self._grid.threads)

    def _all_cast_noise(self) -> tuple[np.ndarray, ...]:
        """What the noise of a cast of every ray needs, worked out as :meth:`_angle_jitter` and :meth:`_apply_noise`
        work it out (the same arithmetic): the jitter (its buffer, rays and scale), the rays with a range noise,
        their proportional noise and the square root of their constant one, buffers for U' and G."""
        angle_noise = self._ray_noise[:, 2]
        jitter_rays = np.flatnonzero(angle_noise != 0.0)
        jitter_scale = self._increment[self._ranger_of_ray[jitter_rays]] * angle_noise[jitter_rays] / 2
        noisy_rays = np.flatnonzero(np.any(self._ray_noise != 0.0, axis=1))
        const, prop = self._ray_noise[noisy_rays, 0], self._ray_noise[noisy_rays, 1]
        jitter = np.zeros(len(self._owner)) if self._angle_noisy else self._no_jitter
        return (jitter, jitter_rays, jitter_scale, noisy_rays, prop, np.sqrt(const), np.empty(noisy_rays.size),
                np.empty(noisy_rays.size))

    def _angle_jitter(self, ray_due: np.ndarray | None) -> np.ndarray:
        """Stage's beam-direction noise inc·a·U/2 for due beams (all when None) of rangers with an angle
        noise, else 0."""
        jitter = np.zeros(len(self._owner))
        angle_noise = self._ray_noise[:, 2]
        rays = np.flatnonzero((angle_noise != 0.0) if ray_due is None else ray_due & (angle_noise != 0.0))
        if rays.size:
            scale = self._increment[self._ranger_of_ray[rays]] * angle_noise[rays] / 2
            jitter[rays] = scale * self._rng.uniform(-1.0, 1.0, len(rays))
        return jitter

    def _apply_noise(self, ranges: np.ndarray, ray_due: np.ndarray) -> np.ndarray:
        """Stage's per-beam noise for rangers that have some; other beams pass unchanged."""
        noise = self._ray_noise
        noisy_ray = ray_due & np.any(noise != 0.0, axis=1)
        if not noisy_ray.any():
            return ranges
        out = ranges.copy()
        rays = np.flatnonzero(noisy_ray)
        const, prop = noise[rays, 0], noise[rays, 1]
        u_range = self._rng.uniform(-1.0, 1.0, len(rays))
        gauss = self._rng.normal(0.0, 1.0, len(rays)) * np.sqrt(const)
        hit = ranges[rays] < self._max_range[rays]
        out[rays] = np.where(hit, ranges[rays] + ranges[rays] * prop * u_range + gauss, ranges[rays])
        return out

    def _tables_by_height(self, robots: list[RobotSpec]) -> list[_BeamTable]:
        """The rays of each height with what they read of their rangers and robots: the robots' alone, made once
        and shared by every world these rangers are moved over (:meth:`over`): a vector env's worlds hold one
        copy (20 KB for 512 beams), not one each, and a reset slices none."""
        returns = np.array([r.model.ranger_return for r in robots], dtype=np.float32)
        tables = []
        for height in np.unique(self._ray_height):
            rays = np.flatnonzero(self._ray_height == height)
            whole = rays.size == self._owner.size  # all in one group: the arrays themselves, not copies
            tables.append(_BeamTable(
                float(height), rays, *((self._owner, self._ranger_of_ray, self._angle, self._max_range) if whole else
                                      (self._owner[rays], self._ranger_of_ray[rays], self._angle[rays],
                                       self._max_range[rays])),
                np.array([r.z_band[0] <= height <= r.z_band[1] for r in robots], dtype=bool) & (returns >= 0),
                returns))
        return tables

    def _height_groups(self) -> list[HeightGroup]:
        """The beam tables over the static world: each height's static layer and its caster (heights that see the
        same static cells share one), each with a robot layer of its own."""
        groups = []
        static, casters = self._static, self._casters
        for table in self._beam_tables:
            occupied, intensity = static.sensing_tiles(table.height)
            key = (self._backend.name, self._grid.threads, id(occupied))
            caster = casters.get(key)
            if caster is None:  # kept once made: worlds switching kernels on background threads agree on one
                caster = casters.setdefault(key, self._backend.caster(occupied, static.resolution, static.origin_xy,
                                                                      threads=self._grid.threads))
            groups.append(HeightGroup(
                rays=table.rays, owner=table.owner, ranger=table.ranger, angle=table.angle,
                max_range=table.max_range, caster=caster, robots=caster.robot_layer(), intensity=intensity,
                robot_visible=table.visible, robot_return=table.returns,
            ))
        return groups

    def _ranger_slices(self) -> list[slice]:
        counts = np.bincount(self._ranger_of_ray, minlength=len(self._rangers))
        ends = np.cumsum(counts)
        return [slice(int(e - n), int(e)) for n, e in zip(counts, ends, strict=True)]

