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
    flags, odometry, scans and clock, bit for bit), the fused steps of all those that take one (compiled kernels,
    every ranger due at every step, no watchdog, the same interval and robots) in one compiled call (its worlds
    shared among the threads of the first that joined, :attr:`Simulation.threads`, the same answers): a vector
    env's worlds, whose per-world calls and Python cost more than the step's own work at one robot a world.

    The batch *holds* the simulations that take its call: their state lives here between steps, a row per slot,
    and a step runs no Python per world. A held simulation is behind until :meth:`sync` brings it up to date (its
    poses, flags, odometry, velocities, scans and clock as its own steps would have left them; arrays never
    written afterwards, as :meth:`Simulation.step` makes them): sync it before reading or changing it. Its
    commands and their times are rows of the batch's (``step``'s ``commands`` write them; after a sync,
    :meth:`Simulation.set_velocity` does too). A simulation synced and then changed (a reset, a pose set, a step
    of its own) is taken in again at its next step, from its arrays as they are then; one that cannot take the
    call steps on its own. When every simulation of a step was held (:attr:`whole`), :attr:`poses`,
    :attr:`stalled`, :attr:`velocities` and :attr:`ranges` (every beam, float32) are the stepped slots' new
    state, a row per slot (the other rows as they were before the step, their ranges unset)."""

    def __init__(self, size: int) -> None:
        """``size``: the slots, one per world."""
        self.size = size
        self._fused: FusedBatch | None = None  # made when a compiled world first joins
        self._shape: _BatchShape | None = None  # of the first that joined: that of every one that joins
        self._held: list[Simulation | None] = [None] * size
        self._given: list[tuple[object, ...] | None] = [None] * size  # per synced slot: what its simulation holds
        self._unsure: set[int] = set()  # held slots synced since their last step: their simulations may have changed
        self._noisy: dict[int, RangerSensing] = {}  # held slots whose casts draw noise, by slot
        self._behind = np.zeros(size, dtype=bool)  # held slots stepped here since their simulation's last sync
        self._clock = np.zeros(size, dtype=np.int64)  # each slot's sim time (µs) and update count
        self._updates = np.zeros(size, dtype=np.int64)
        # poses, layers, odometry, stalled, errors, uses_odom, commands, command times, velocities, ranges, intensities
        self._state: tuple[np.ndarray, ...] = ()
        self._motion: tuple = ()  # the body velocities' call: motion, drives, wheelbases and bounds of all slots
        self._last: tuple[list[Simulation], list[int], np.ndarray, list[int]] | None = None  # the last step's sims,
        # slots, slots as an array and noisy slots, when all of them were held: the next like it needs no sorting
        self.poses = self.stalled = self.velocities = self.ranges = np.empty(0)
        self.whole = False  #: whether every simulation of the last step joined the compiled call

    def step(self, sims: Sequence[Simulation], slots: Sequence[int], commands: np.ndarray | None = None,
             robot: int = 0) -> None:
        """Step each of ``sims`` once; ``slots[k]``: the slot of ``sims[k]``, the same for a world at every step
        (an env's world index), whatever subset steps. ``commands``: (len(sims), 3) velocities (vx, vy, va) that
        robot ``robot`` of each is commanded with (:meth:`Simulation.set_velocity`) just before the step."""
        slots = list(slots)
        last = self._last
        if last is not None and not self._unsure and slots == last[1] and list(sims) == last[0]:
            joined, rows, noisy = last[2], None, last[3]
        else:
            joined_list, rows_list, alone = self._sort(sims, slots)
            for k in alone:  # each as Simulation.step steps it
                if commands is not None:
                    sims[k].set_velocity(robot, *commands[k].tolist())
                sims[k].step()
            joined = np.array(joined_list, dtype=np.int64)
            rows = None if len(rows_list) == len(slots) else np.array(rows_list, dtype=np.int64)
            noisy = [slot for slot in joined_list if slot in self._noisy]
            self._last = (list(sims), slots, joined, noisy) if not alone else None
        self.whole = bool(joined.size) and self._last is not None
        if joined.size:
            self._step_held(joined, noisy, commands if commands is None or rows is None else commands[rows], robot)

    def sync(self, slots: Sequence[int] | None = None) -> None:
        """Bring the held simulations of ``slots`` (every held one by default) up to date, as their own steps would
        have left them; they may be read and changed then (the batch checks them at their next step)."""
        chosen = [slot for slot in range(self.size) if self._held[slot] is not None] if slots is None else slots
        poses, layers, odometry, stalled, _, _, _, _, velocities, published, intensity = self._state or (None,) * 11
        for slot in chosen:
            sim = self._held[slot]
            if sim is None:
                continue
            if self._behind[slot]:
                sim.sim_time_us, sim._updates = int(self._clock[slot]), int(self._updates[slot])
                sim.true_poses, sim.stalled, sim.odometry_poses, sim._layer_poses, sim.velocities = \
                    poses[slot], stalled[slot], odometry[slot], layers[slot], velocities[slot]
                sim._sensing.record_all(published[slot], intensity[slot], sim.sim_time_us)
                self._behind[slot] = False
            self._given[slot] = self._holding(sim)
            self._unsure.add(slot)

    @staticmethod
    def _holding(sim: Simulation) -> tuple[object, ...]:
        """What a held simulation holds that anything changing it replaces: told apart by identity."""
        return (sim.true_poses, sim.stalled, sim.odometry_poses, sim._layer_poses, sim.odom_errors, sim.commands,
                sim.last_command_us, sim._fused, sim._sensing)

    def _sort(self, sims: Sequence[Simulation], slots: list[int]) -> tuple[list[int], list[int], list[int]]:
        """Which of ``sims`` take the call (their slots, and their positions in ``sims``), each taken in unless it
        is held and unchanged, and which step on their own (positions)."""
        joined, rows, alone = [], [], []
        copied = False  # whether the stacked rows below are written into copies (synced simulations hold views)
        for k, (sim, slot) in enumerate(zip(sims, slots, strict=True)):
            held = self._held[slot] is sim
            if held and slot not in self._unsure:
                joined.append(slot)
                rows.append(k)
                continue
            self._unsure.discard(slot)
            given = self._given[slot]
            if (held and given is not None and not self._behind[slot] and sim.watchdog_timeout <= 0
                    and all(a is b for a, b in zip(given, self._holding(sim), strict=True))):
                joined.append(slot)  # synced, then left as it was
                rows.append(k)
            elif self._admit(sim, slot):
                if not copied:
                    self._state = tuple(array.copy() for array in self._state[:4]) + self._state[4:]
                    copied = True
                self._take_in(sim, slot)
                joined.append(slot)
                rows.append(k)
            else:
                self._release(slot)
                alone.append(k)
        return joined, rows, alone

    def _admit(self, sim: Simulation, slot: int) -> bool:
        """Whether ``sim`` takes fused steps that can share the compiled call (of the shape of the first admitted),
        every ranger due at every step and no watchdog; if so its fused step is held in ``slot``."""
        fused = sim._fused  # not None: compiled kernels running (none while a background upgrade is under way)
        if (fused is None or sim.watchdog_timeout > 0
                or not sim._sensing.due_every_step(sim.sim_time_us + sim.interval_us, sim.interval_us)):
            return False
        shape = _BatchShape.of(sim)
        if self._fused is None:
            batch = backend_for(sim.kernels).fused_batch
            if batch is None:
                return False
            self._fused, self._shape = batch(sim.threads), shape
        if shape != self._shape or not self._fused.fits(fused):
            return False
        if not self._state:
            self._start(sim)
        self._fused.hold(slot, fused)
        return True

    def _take_in(self, sim: Simulation, slot: int) -> None:
        """Hold ``sim`` in ``slot``: its state copied into the slot's rows, its commands and their times made views
        of the batch's (written in place from now on)."""
        poses, layers, odometry, stalled, errors, uses_odom, commands, commanded, *_ = self._state
        poses[slot], stalled[slot], odometry[slot] = sim.true_poses, sim.stalled, sim.odometry_poses
        layers[slot], errors[slot], uses_odom[slot] = sim._layer_poses, sim.odom_errors, sim._uses_odom
        commands[slot], commanded[slot] = sim.commands, sim.last_command_us
        sim.commands, sim.last_command_us = commands[slot], commanded[slot]
        self._clock[slot], self._updates[slot] = sim.sim_time_us, sim._updates
        self._held[slot], self._given[slot] = sim, None
        self._behind[slot] = False
        if sim._sensing.noisy:
            self._noisy[slot] = sim._sensing
        else:
            self._noisy.pop(slot, None)

    def _release(self, slot: int) -> None:
        """The slot holds no simulation (its last one steps on its own)."""
        self._held[slot] = self._given[slot] = None
        self._unsure.discard(slot)
        self._noisy.pop(slot, None)
        self._behind[slot] = False

    def _step_held(self, slots: np.ndarray, noisy: list[int], commands: np.ndarray | None, robot: int) -> None:
        """The compiled call for the held simulations of ``slots``, after robot ``robot`` of each is commanded
        with its row of ``commands`` (when given), stamped at its time before the step."""
        poses, layers, odometry, stalled, errors, uses_odom, given, commanded, velocities, published, intensity = \
            self._state
        clock, updates = self._clock, self._updates
        if commands is not None:
            given[slots, robot] = commands
            commanded[slots, robot] = clock[slots]
        for slot in noisy:
            self._noisy[slot].draw_all_noise()
        clock[slots] += self._shape.interval_us
        motion, drives, wheelbases, bounds = self._motion
        n = given.shape[1]
        moved = motion.body_velocities(given.reshape(-1, 3), drives, wheelbases, bounds).reshape(-1, n, 3)
        result = self._fused.step(slots, poses, layers.copy(), updates % 2, odometry, moved, errors,
                                  self._shape.interval_us / MICROSECONDS, uses_odom, stalled)
        updates[slots] += 1
        scans, scan_intensity = result.scans
        carried = self._behind.copy()
        carried[slots] = False
        if carried.any():  # slots behind that did not step: their last step's velocities and scans carried over
            moved[carried], scans[carried], scan_intensity[carried] = \
                velocities[carried], published[carried], intensity[carried]
        self._behind[slots] = True
        self._state = (result.poses, result.layers, result.odometry, result.stalled, errors, uses_odom, given,
                       commanded, moved, scans, scan_intensity)
        self.poses, self.stalled, self.velocities, self.ranges = result.poses, result.stalled, moved, scans

    def _start(self, sim: Simulation) -> None:
        """The stacked state and the body velocities' call for robots like those of ``sim`` in every slot."""
        w, n = self.size, len(sim.robots)
        beams = self._fused.beams
        self._state = (np.zeros((w, n, 3)), np.zeros((w, 2, n, 3)), np.zeros((w, n, 3)), np.zeros((w, n), dtype=bool),
                       np.zeros((w, n, 4)), np.zeros((w, n), dtype=bool), np.zeros((w, n, 3)),
                       np.zeros((w, n), dtype=np.int64), np.zeros((w, n, 3)), np.zeros((w, beams), dtype=np.float32),
                       np.zeros((w, beams), dtype=np.float32))
        self._motion = (backend_for(sim.kernels).motion, group_by_drive([r.settings.drive for r in sim.robots] * w),
                        np.tile(sim.drives.wheelbases, w), np.tile(sim.drives.bounds, (w, 1)))
