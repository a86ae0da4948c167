"""The ROS-free simulation: a Stage world stepped at ``interval_sim``, deterministic for a seed.

One :meth:`Simulation.step` advances sim time by one ``interval_sim`` and, in this order: applies the
watchdog, turns commands into body velocities (drive + ``velocity_bounds``), moves the robots one by one as
Stage does (refusing moves into obstacles: the robot stalls; Stage's two raster layers, see
:mod:`stage_sim.sim.collision`), updates odometry, and casts every due laser from the *new* poses, so scans
and odometry agree with the ground truth of the same stamp (Stage lags one step; we do not).

Usage::

    sim = Simulation.from_world("worlds/rooms.world", seed=1)
    sim.set_velocity(0, 0.5, 0.0, 0.2)
    for _ in range(10):
        sim.step()
    sim.true_poses[0], sim.odometry_poses[0], sim.scans[0][0].ranges

The state arrays it exposes (poses, odometry, velocities, stall flags, the measured beams) are never written
once exposed: every change replaces the array. A bag recording keeps a reference to each step's instead of a
copy (:mod:`stage_sim.bags.step_state`).
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from stage_sim.backend import resolve_kernels, resolve_threads
from stage_sim.maps.raster import StaticRaster, build_static_raster, with_models
from stage_sim.sim.backends import Backend, FusedBatch, backend_for
from stage_sim.sim.collision import Bodies, Contact, GridFrame
from stage_sim.sim.drives import DriveTable, group_by_drive
from stage_sim.sim.kernel_upgrade import CompiledParts, KernelUpgrade, note_kernels_running, upgrade_wanted
from stage_sim.sim.kinematics import true_velocities
from stage_sim.sim.odometry import draw_odom_errors, relative_pose
from stage_sim.sim.rangers import MeasuredBeams, RangerSensing, Scan
from stage_sim.sim.robots import RobotSpec, build_robots
from stage_sim.worldfile.description import Model, WorldDescription, WorldWarning

if TYPE_CHECKING:
    from stage_sim.sim.compiled import FusedResult

# Sim time is kept in integer microseconds, like Stage, so that no rounding drift accumulates.
MICROSECONDS = 1_000_000


@dataclass(frozen=True)
class RobotState:
    """A snapshot of one robot, for callers that want one object rather than the batched arrays."""

    true_pose: tuple[float, float, float]
    odometry_pose: tuple[float, float, float]
    velocity: tuple[float, float, float]
    stalled: bool


class Simulation:
    """A Stage world in motion: robots, their odometry and their lasers."""

    def __init__(
        self, description: WorldDescription, seed: int | None = None, watchdog_timeout: float = 0.0,
        kernels: str | None = None, threads: int | None = None,
    ) -> None:
        """``kernels``: "numba" or "numpy" (identical results; default numba, ``$STAGE_SIM_KERNELS``);
        ``threads``: kernel threads, 0 = all cores (identical results for any value; default 1,
        ``$STAGE_SIM_THREADS``). See :mod:`stage_sim.backend`."""
        self._kernels_asked = kernels
        self.threads = resolve_threads(threads)
        self.interval_us = max(1, round(description.settings.interval_sim * MICROSECONDS))
        self.watchdog_timeout = watchdog_timeout
        self._world_warnings: list[WorldWarning] = list(description.warnings)
        self.robots: list[RobotSpec] = build_robots(description, self._world_warnings)
        self._bodies = Bodies.from_polygons([list(r.body) for r in self.robots])
        n = len(self.robots)
        self._start = np.array([r.start for r in self.robots], dtype=np.float64).reshape(n, 3)
        self._drives = DriveTable(
            group_by_drive([r.settings.drive for r in self.robots]),
            np.array([r.settings.wheelbase for r in self.robots], dtype=np.float64),
            np.array([r.settings.velocity_bounds for r in self.robots], dtype=np.float64).reshape(n, 8))
        self._uses_odom = np.array([r.settings.localization == "odom" for r in self.robots], dtype=bool)
        self._odom_origin = np.array(
            [self._odometry_origin(r) for r in self.robots], dtype=np.float64).reshape(n, 3)
        starts = [(r.start[0], r.start[1], r.radius + description.settings.resolution) for r in self.robots]
        self._furnish(description, build_static_raster(description, starts))
        self.reset(seed)

    def with_static_models(self, description: WorldDescription, seed: int | None = None) -> Simulation:
        """A simulation of ``description``, this world with static models added (an episode's obstacles): what
        ``Simulation(description, seed)`` with this one's watchdog, kernels and threads gives.

        Built from this simulation's robots and raster, only the new bodies traced (the grid grown when they
        reach past it), when ``description`` keeps this world's top-level models (the very objects, in order),
        adds no robot and puts the new static models after this world's (an environment's reset builds one
        world per episode); else built from scratch. With no model added it is this very world, and shares all
        that is static with this simulation: the raster, its tiles and the rays' casters (a vector env's worlds
        of one world file hold them once)."""
        added = self._added_static(description)
        if added is None:
            return Simulation(description, seed, self.watchdog_timeout, self._kernels_asked, self.threads)
        # Traced on the kernels the new simulation starts on: not this one's, which a base world that is never
        # stepped (an env's) keeps on numpy for good, its upgrade never adopted.
        static = with_models(self.static, added, backend_for(self.starting_kernels()).trace) if added else self.static
        sim = copy.copy(self)  # shares what never changes (robots, bodies, drives); the state is reset below
        sim._furnish(description, static, self._sensing)
        sim.reset(seed)
        return sim

    def _added_static(self, description: WorldDescription) -> list[Model] | None:
        """The top-level models ``description`` adds to this world, or None when it is not this world with static
        models appended (see :meth:`with_static_models`)."""
        own = self.description.models
        ids = {id(model) for model in own}
        kept = [model for model in description.models if id(model) in ids]
        added = [(k, model) for k, model in enumerate(description.models) if id(model) not in ids]
        last_static = max((k for k, model in enumerate(description.models)
                           if id(model) in ids and model.type != "position"), default=-1)
        if (len(kept) != len(own) or any(a is not b for a, b in zip(kept, own, strict=True))
                or any(k < last_static for k, _ in added)
                or any(part.type == "position" for _, model in added for part in model.walk())):
            return None
        return [model for _, model in added]

    def _upgrade_wanted(self) -> bool:
        """Whether a simulation of this world starts on numpy while numba loads in the background (nobody chose
        the kernels; see sim/kernel_upgrade.py)."""
        beams = sum(ranger.sensor.samples for robot in self.robots for ranger in robot.rangers)
        return upgrade_wanted(self._kernels_asked, beams)

    def starting_kernels(self) -> str:
        """The kernels a simulation of this world starts on (one :meth:`with_static_models` makes, too)."""
        return "numpy" if self._upgrade_wanted() else resolve_kernels(self._kernels_asked)

    def _furnish(self, description: WorldDescription, static: StaticRaster,
                 rangers_of: RangerSensing | None = None) -> None:
        """Everything that depends on the static world: its raster, the kernels (on numpy until numba is
        loaded in the background when nobody chose, sim/kernel_upgrade.py), the contact checker, the ranger
        sensing (``rangers_of``'s rangers over this world when given: the same robots), and the warnings about
        robots that start inside an obstacle."""
        self.description = description
        self.static = static
        self.kernels = self.starting_kernels()
        self._upgrade = KernelUpgrade(self) if self._upgrade_wanted() else None
        self._collision, self._sensing = self.build_parts(self.kernels, rangers_of)
        self._motion = backend_for(self.kernels).motion
        self._fused = backend_for(self.kernels).fused(self._collision, self._sensing.single_cast(), self.threads,
                                                      self._drives)
        note_kernels_running(self.kernels)
        self.warnings = list(self._world_warnings)
        for index in np.flatnonzero(self._collision.overlapping(self._start)):
            robot = self.robots[index]
            self.warnings.append(WorldWarning(
                f"robot '{robot.name}' starts overlapping an obstacle or another robot: it will stall until "
                "it moves clear", robot.model.location))

    @classmethod
    def from_world(
        cls, world: str | Path | WorldDescription, seed: int | None = None, watchdog_timeout: float = 0.0,
        kernels: str | None = None, threads: int | None = None,
    ) -> Simulation:
        """A simulation of a world file (path) or of an already loaded description."""
        if not isinstance(world, WorldDescription):
            from stage_sim.worldfile.loader import load_world

            world = load_world(world)
        return cls(world, seed=seed, watchdog_timeout=watchdog_timeout, kernels=kernels, threads=threads)

    # -- lifecycle -------------------------------------------------------------------------------------

    def reset(self, seed: int | None = None) -> None:
        """Back to the start: time 0, start poses, no motion, fresh scans; a new seed redraws the random parts."""
        self.rng = np.random.default_rng(seed)
        self.sim_time_us = 0
        self._updates = 0  # Stage's update count: its parity picks the raster layer the moves work in
        self.odom_errors = draw_odom_errors([r.settings.odom_error for r in self.robots], self.rng)
        self._sensing.reset(self.rng)
        self.reset_positions()
        self._sensing.sense(self.true_poses, self.sim_time)

    def reset_positions(self) -> None:
        """What stageros' ``reset_positions`` does here: start poses, no stall, no velocity, fresh odometry.

        Sim time and the random state carry on; every laser scans again at the next step (not now, so that a
        storm of resets costs nothing). Call it between steps (the ROS layer does)."""
        n = len(self.robots)
        self.true_poses = self._start.copy()
        self.commands = np.zeros((n, 3))
        self.velocities = np.zeros((n, 3))
        self.stalled = np.zeros(n, dtype=bool)
        self._layer_poses = np.stack([self._start, self._start])  # where each of Stage's two layers has them
        self.last_command_us = np.full(n, self.sim_time_us, dtype=np.int64)
        self._oldest_command_us = self.sim_time_us
        self.odometry_poses = np.where(
            self._uses_odom[:, None], relative_pose(self._start, self._odom_origin), self._start)
        self._sensing.invalidate()

    # -- inputs ----------------------------------------------------------------------------------------

    def set_velocity(self, robot: int, vx: float, vy: float, va: float) -> None:
        """Command robot ``robot`` (Stage ``SetSpeed``): used from the next step until replaced."""
        self.commands[robot] = (vx, vy, va)
        self.last_command_us[robot] = self.sim_time_us

    def set_velocities(self, robots: np.ndarray, commands: np.ndarray) -> None:
        """Command several robots at once, ``commands[k]`` = (vx, vy, va) for robot ``robots[k]``: what
        :meth:`set_velocity` does for each, in one array operation (the RL envs command every agent per step)."""
        self.commands[robots] = commands
        self.last_command_us[robots] = self.sim_time_us

    def set_pose(self, robot: int, x: float, y: float, yaw: float) -> None:
        """Put robot ``robot`` at a new true pose between steps, as dragging a model in Stage's window does.

        The stall flag clears and the lasers scan again at the next step; commands, velocity and odometry
        carry on (Stage's odometry integrates the robot's own motion, so a moved robot's odometry does not
        jump). Raises ``ValueError`` for a non-finite pose and ``IndexError`` for an unknown robot."""
        if not all(np.isfinite((x, y, yaw))):
            raise ValueError(f"pose must be finite, got ({x}, {y}, {yaw})")
        if not 0 <= robot < len(self.robots):
            raise IndexError(f"no robot {robot} (the world has {len(self.robots)})")
        self.true_poses = self.true_poses.copy()
        self.true_poses[robot] = (x, y, float(np.remainder(yaw + np.pi, 2 * np.pi) - np.pi))
        self.stalled = self.stalled.copy()
        self.stalled[robot] = False
        self._layer_poses = self._layer_poses.copy()
        self._layer_poses[:, robot] = self.true_poses[robot]  # Stage's SetPose maps both layers
        self.odometry_poses = np.where(self._uses_odom[:, None], self.odometry_poses, self.true_poses)
        self._sensing.invalidate()

    # -- stepping --------------------------------------------------------------------------------------

    def step(self) -> None:
        """Advance the world by one ``interval_sim``."""
        self._advance(None, ())

    def fused_next(self) -> bool:
        """Whether the next step is one compiled call that casts every ranger, with no watchdog to apply: a step
        :meth:`step_with` can make."""
        return (self._fused is not None and self.watchdog_timeout <= 0
                and self._sensing.all_due(self.sim_time_us + self.interval_us))

    def step_with(self, kernel: Callable[..., int], arguments: tuple) -> bool:
        """:meth:`step`, when :meth:`fused_next`, with its compiled call made by ``kernel``, a compiled function
        that takes :func:`~stage_sim.sim.fused_kernels.commanded_step`'s arguments, then ``arguments``, and calls
        it with them, returning its answer. Before the call it may write the robots' commands (stamped at the
        step's start: :meth:`set_velocities`), after it read the new state: an RL task's step in one call.

        Returns whether the call's view of the scans holds. It does not, rarely, when the robot layer was too
        small for the cast: the call's own cast is then skipped and the rays are cast again into a grown layer
        after it (:attr:`measured_beams` has them). ValueError, the step not made, when not :meth:`fused_next`."""
        if self.watchdog_timeout > 0:
            raise ValueError("step_with makes the steps fused_next() announces: this one applies a watchdog")
        return not self._advance(kernel, arguments).grown

    def _advance(self, kernel: Callable[..., int] | None, arguments: tuple) -> FusedResult | None:
        """One step (:meth:`step`; its compiled call ``kernel``'s when given, :meth:`step_with`); the fused step's
        result, None when it stepped role by role."""
        fused, now_us = self._fused is not None, self.sim_time_us + self.interval_us
        cast = fused and self._sensing.all_due(now_us)
        if kernel is not None and not cast:
            raise ValueError("step_with makes the steps fused_next() announces: this one is not one call")
        self.sim_time_us = now_us
        dt = self.interval_us / MICROSECONDS
        if self.watchdog_timeout > 0:
            self._stop_silent_robots()
        layer = self._updates % 2
        result = None
        if cast or (fused and self._sensing.none_due(now_us)):  # a fused step casts all rangers or none
            result = self._step_fused(layer, dt, cast, kernel, arguments)
        else:
            self.velocities = self._body_velocities()
            self._step_by_roles(layer, dt)
        if self._upgrade is not None:
            self._adopt(self._upgrade.poll())
        return result

    def _stop_silent_robots(self) -> None:
        """The watchdog: zero the commands of the robots not commanded for ``watchdog_timeout``. Commands only
        move ``last_command_us`` forward, so no robot can be silent before the oldest command seen at the last
        look has timed out: until then a step skips the look (a robot driven at 10 Hz is never looked at)."""
        timeout_us = round(self.watchdog_timeout * MICROSECONDS)
        if self.sim_time_us - self._oldest_command_us < timeout_us:
            return
        silent = (self.sim_time_us - self.last_command_us) >= timeout_us
        self.commands[silent] = 0.0
        self._oldest_command_us = int(self.last_command_us.min())

    def _step_fused(self, layer: int, dt: float, cast: bool, kernel: Callable[..., int] | None = None,
                    arguments: tuple = ()) -> FusedResult:
        """The body velocities, moves, odometry and (when ``cast``) every ranger's scan of a step in one compiled
        call (``kernel``'s when given, see :meth:`step_with`), the same as :meth:`_body_velocities` and
        :meth:`_step_by_roles` give (the backend's fused step)."""
        if cast:
            self._sensing.draw_all_noise()
        fused = self._fused.step(self.commands, self.true_poses, self._layer_poses, layer, self.stalled,
                                 self.odometry_poses, self.odom_errors, self._uses_odom, dt, cast, kernel, arguments)
        self.true_poses, self.stalled, self.odometry_poses, self._layer_poses, self.velocities = \
            fused.poses, fused.stalled, fused.odometry, fused.layers, fused.velocities
        self._updates += 1
        if cast:
            self._sensing.record_all(*fused.scans, self.sim_time_us)
        return fused

    def _step_by_roles(self, layer: int, dt: float) -> None:
        """The moves, odometry and scans of a step, one role after the other (what the fused step does at once)."""
        moving = (self.velocities != 0.0).any(axis=1)
        moved, refused, layer_poses = self._collision.resolve(
            self.true_poses, self._layer_poses[layer], self.velocities, dt, moving)
        self._layer_poses = self._layer_poses.copy()
        self._layer_poses[layer] = layer_poses
        self._updates += 1
        self.stalled = np.where(moving, refused, self.stalled)
        self.true_poses = moved
        self.odometry_poses = self._odometry(moved, dt)
        # The rays read the layer just built (Stage's sensors of the next update read it), not the true poses.
        self._sensing.sense(self.true_poses, self.sim_time, self._collision.raster(layer_poses))

    def wait_for_kernels(self, timeout: float | None = None) -> None:
        """Block until a background switch to the compiled kernels (if any is under way) is ready; the
        switch itself happens at the end of the next step. For benchmarks that must time one implementation."""
        if self._upgrade is not None:
            self._upgrade.wait(timeout)

    def _adopt(self, parts: CompiledParts | None) -> None:
        """Continue on the compiled parts: the new sensing takes over the scans, schedule and noise state."""
        if parts is None:
            return
        parts.sensing.adopt(self._sensing)
        self._collision, self._sensing, self._motion = parts.collision, parts.sensing, parts.backend.motion
        self._fused = parts.fused
        self.kernels = parts.backend.name
        self._upgrade = None

    def _body_velocities(self) -> np.ndarray:
        """The body velocities the commands give (drive + ``velocity_bounds``)."""
        drives = self._drives
        return self._motion.body_velocities(self.commands, drives.groups, drives.wheelbases, drives.bounds)

    def _odometry(self, moved: np.ndarray, dt: float) -> np.ndarray:
        """Odometry after the step: integrated with the odom errors, or the true pose (gps localization)."""
        return self._motion.odometry(self.odometry_poses, self.velocities, self.odom_errors, dt, self._uses_odom,
                                     moved)

    # -- queries ---------------------------------------------------------------------------------------

    @property
    def sim_time(self) -> float:
        """Simulated seconds since the start (or the last :meth:`reset`)."""
        return self.sim_time_us / MICROSECONDS

    @property
    def start_poses(self) -> np.ndarray:
        """The robots' start poses (N, 3), where :meth:`reset_positions` puts them."""
        return self._start.copy()

    @property
    def drives(self) -> DriveTable:
        """What turns its robots' commands into body velocities: drive groups, wheelbases, velocity bounds."""
        return self._drives

    @property
    def interval(self) -> float:
        """Seconds of sim time per step."""
        return self.interval_us / MICROSECONDS

    @property
    def true_velocities(self) -> np.ndarray:
        """Each robot's true twist (:func:`~stage_sim.sim.kinematics.true_velocities`): read every step by stageros;
        a recording derives it in its writer process from the velocities and stall flags."""
        return true_velocities(self.velocities, self.stalled)

    @property
    def scans(self) -> list[list[Scan]]:
        """Latest scan of every ranger, per robot (``scans[robot][ranger]``)."""
        return self._sensing.latest

    @property
    def measured_beams(self) -> MeasuredBeams | None:
        """The beams of the last step that cast any, every ranger's end to end (:attr:`scans` are views of
        them); None before the first."""
        return self._sensing.measured

    def beams_of(self, robot: int, ranger: int = 0) -> slice:
        """Where the beams of ranger ``ranger`` of robot ``robot`` lie among every ranger's (its scans' ranges are
        these of :attr:`measured_beams`, and of a :class:`SimulationBatch`'s ``ranges`` row)."""
        return self._sensing.beams_of(robot, ranger)

    def state(self, robot: int) -> RobotState:
        """One robot's true pose, odometry, applied velocity and stall flag."""
        return RobotState(
            tuple(self.true_poses[robot]), tuple(self.odometry_poses[robot]),
            tuple(self.velocities[robot]), bool(self.stalled[robot]),
        )

    # -- construction helpers --------------------------------------------------------------------------

    def build_parts(self, kernels: str, rangers_of: RangerSensing | None = None) -> tuple[Contact, RangerSensing]:
        """The collision checker and the ranger sensing of this world on ``kernels`` (stateless until used);
        ``rangers_of``: a sensing of these robots whose beam tables (and casters, over the same raster) to share,
        by default this simulation's own (a switch of kernels: the worlds of a vector env share them still)."""
        if rangers_of is None:
            rangers_of = getattr(self, "_sensing", None)  # none yet while the simulation is first furnished
        backend = backend_for(kernels)
        grid = GridFrame(self.static.shape, self.static.resolution, self.static.origin_xy, self.threads)
        collision = self._make_collision_checker(backend, grid)
        if rangers_of is not None:
            return collision, rangers_of.over(self.static, grid, backend, collision.raster)
        return collision, RangerSensing(self.robots, self.static, self._bodies, grid, backend, collision.raster)

    def _make_collision_checker(self, backend: Backend, grid: GridFrame) -> Contact:
        bands = sorted({r.z_band for r in self.robots})
        layers = [self.static.collision_tiles(*band) for band in bands]
        layer_of_robot = np.array([bands.index(r.z_band) for r in self.robots], dtype=np.int64)
        collides = np.array([r.model.obstacle_return for r in self.robots], dtype=bool)
        return backend.contact(self._bodies, grid, layers, layer_of_robot, collides)

    @staticmethod
    def _odometry_origin(robot: RobotSpec) -> tuple[float, float, float]:
        origin = robot.settings.localization_origin
        if origin is None:
            return robot.start
        return (origin.x, origin.y, origin.yaw)


@dataclass(frozen=True)
class _BatchShape:
    """What every simulation of a :class:`SimulationBatch`'s call shares: the interval, and robots of the same
    drives and bounds in the same order (their body velocities are worked out in one call)."""

    interval_us: int
    drives: tuple[str, ...]
    wheelbases: bytes
    bounds: bytes

    @classmethod
    def of(cls, sim: Simulation) -> _BatchShape:
        return cls(sim.interval_us, tuple(r.settings.drive for r in sim.robots), sim.drives.wheelbases.tobytes(),
                   sim.drives.bounds.tobytes())


class SimulationBatch:
    """Simulations stepped together, each as its own :meth:`Simulation.step` would step it (the same poses,
    flags, odometry and scans, bit for bit), the fused steps of all those that take one (compiled kernels,
    every ranger due, the same interval and robots) in one compiled call (its worlds shared among the threads
    of the first that joined, :attr:`Simulation.threads`, the same answers): a vector env's worlds, whose
    per-world calls and their Python cost more than the step's own work at one robot a world.

    The worlds' state stays stacked here between steps, a row per slot, and each simulation's arrays are views
    of its row (new arrays every step, as :meth:`Simulation.step` makes them; its commands stay one array, which
    :meth:`Simulation.set_velocities` writes in place); a row is copied in again only when its simulation's
    arrays are not the views it was given (a reset, a pose set, a step of its own). When every simulation of a
    step joined the call (:attr:`whole`), :attr:`poses`, :attr:`stalled`, :attr:`velocities` and
    :attr:`ranges` (every beam, float32) are the stepped slots' new state, a row per slot (the other rows as
    they were before the step, their ranges unset)."""

    def __init__(self, size: int) -> None:
        """``size``: the slots, one per world."""
        self.size = size
        self._fused: FusedBatch | None = None  # made when a compiled world first joins
        self._shape: _BatchShape | None = None  # of the first that joined: that of every one that joins
        self._members: list[tuple[Simulation, object] | None] = [None] * size  # per slot: (simulation, fused step)
        self._given: list[tuple[object, ...] | None] = [None] * size  # per slot: the arrays its simulation holds
        self._state: tuple[np.ndarray, ...] = ()  # poses, layers, odometry, stalled, errors, uses_odom, commands
        self._motion: tuple = ()  # the body velocities' call: motion, drives, wheelbases and bounds of all slots
        self.poses = self.stalled = self.velocities = self.ranges = np.empty(0)
        self.whole = False  #: whether every simulation of the last step joined the compiled call

    def step(self, sims: Sequence[Simulation], slots: Sequence[int]) -> None:
        """Step each of ``sims`` once; ``slots[k]``: the slot of ``sims[k]``, the same for a world at every step
        (an env's world index), whatever subset steps."""
        joined: list[Simulation] = []
        joined_slots: list[int] = []
        alone = False
        for sim, slot in zip(sims, slots, strict=True):
            member = self._members[slot]
            if ((member is not None and member[0] is sim and member[1] is sim._fused) or self._admit(sim, slot)) \
                    and sim._sensing.all_due(sim.sim_time_us + sim.interval_us):
                joined.append(sim)
                joined_slots.append(slot)
            else:  # not a fused step that casts every ranger (as Simulation.step would make it), or of another shape
                sim.step()
                alone = True
        if joined:
            self._step_joined(joined, joined_slots)
        self.whole = bool(joined) and not alone

    def _step_joined(self, sims: list[Simulation], slots: list[int]) -> None:
        """The compiled call for ``sims`` (each has joined), and what each simulation keeps of it."""
        poses, layers, odometry, stalled, errors, uses_odom, commands = self._state
        parity = np.zeros(self.size, dtype=np.int64)
        given_all = self._given
        fresh = False  # whether the rows below are written into copies: the last step's are the simulations' arrays
        for sim, slot in zip(sims, slots, strict=True):
            sim.sim_time_us += sim.interval_us
            if sim.watchdog_timeout > 0:
                sim._stop_silent_robots()
            sim._sensing.draw_all_noise()
            parity[slot] = sim._updates % 2
            given = given_all[slot]
            if (given is None or given[0] is not sim.true_poses or given[1] is not sim.stalled
                    or given[2] is not sim.odometry_poses or given[3] is not sim._layer_poses
                    or given[4] is not sim.odom_errors or given[5] is not sim.commands):
                if not fresh:
                    poses, odometry, stalled, fresh = poses.copy(), odometry.copy(), stalled.copy(), True
                poses[slot], stalled[slot], odometry[slot] = sim.true_poses, sim.stalled, sim.odometry_poses
                layers[slot], errors[slot], uses_odom[slot] = sim._layer_poses, sim.odom_errors, sim._uses_odom
                commands[slot] = sim.commands
                sim.commands = commands[slot]  # the same commands, written in place from now on
        motion, drives, wheelbases, bounds = self._motion
        n = commands.shape[1]
        velocities = motion.body_velocities(commands.reshape(-1, 3), drives, wheelbases, bounds).reshape(-1, n, 3)
        assert self._fused is not None and self._shape is not None
        result = self._fused.step(np.array(slots, dtype=np.int64), [sim._fused for sim in sims], poses,
                                  layers.copy(), parity, odometry, velocities, errors,
                                  self._shape.interval_us / MICROSECONDS, uses_odom, stalled)
        assert result.scans is not None
        published, intensity = result.scans
        for sim, slot in zip(sims, slots, strict=True):
            sim.true_poses, sim.stalled, sim.odometry_poses, sim._layer_poses = given = \
                result.poses[slot], result.stalled[slot], result.odometry[slot], result.layers[slot]
            given_all[slot] = (*given, sim.odom_errors, sim.commands)
            sim.velocities = velocities[slot]
            sim._updates += 1
            sim._sensing.record_all(published[slot], intensity[slot], sim.sim_time_us)
        self._state = (result.poses, result.layers, result.odometry, result.stalled, errors, uses_odom, commands)
        self.poses, self.stalled, self.velocities, self.ranges = result.poses, result.stalled, velocities, published

    def _admit(self, sim: Simulation, slot: int) -> bool:
        """Whether ``sim`` (new in ``slot``, or with new kernels) takes fused steps that can share the compiled call
        (of the shape of the first admitted); if so it becomes the slot's member."""
        fused = sim._fused  # not None: compiled kernels running (none while a background upgrade is under way)
        if fused is None:
            return False
        shape = _BatchShape.of(sim)
        if self._fused is None:
            batch = backend_for(sim.kernels).fused_batch
            if batch is None:
                return False
            self._fused, self._shape = batch(sim.threads), shape
            self._start(sim)
        if shape != self._shape or not self._fused.fits(fused):
            return False
        self._members[slot] = (sim, fused)
        self._given[slot] = None
        return True

    def _start(self, sim: Simulation) -> None:
        """The stacked state and the body velocities' call for robots like those of ``sim`` in every slot."""
        w, n = self.size, len(sim.robots)
        self._state = (np.zeros((w, n, 3)), np.zeros((w, 2, n, 3)), np.zeros((w, n, 3)), np.zeros((w, n), dtype=bool),
                       np.zeros((w, n, 4)), np.zeros((w, n), dtype=bool), np.zeros((w, n, 3)))
        self._motion = (backend_for(sim.kernels).motion, group_by_drive([r.settings.drive for r in sim.robots] * w),
                        np.tile(sim.drives.wheelbases, w), np.tile(sim.drives.bounds, (w, 1)))
