"""The one place where a kernels name (``"numpy"`` or ``"numba"``, :data:`stage_sim.backend.KERNELS`) becomes
code: :func:`backend_for` returns the :class:`Backend` of that name, one implementation per role.

Roles, each with the numpy reference and its compiled twin (identical answers bit for bit, ``tests/sim``,
``tests/sensing``):

* ray casting: :class:`~stage_sim.sensing.casters.RayCaster` (built by
  :func:`~stage_sim.sensing.casters.make_caster`, the sensing layer's builder by name);
* contact: :class:`~stage_sim.sim.collision.Contact` (:class:`~stage_sim.sim.collision.CollisionChecker`,
  :class:`~stage_sim.sim.compiled.CompiledCollisionChecker`);
* motion: :class:`Motion` (:class:`ReferenceMotion`, :class:`~stage_sim.sim.compiled.CompiledMotion`);
* laser returns: :class:`HitIntensity` (:func:`~stage_sim.sim.returns.hit_intensity`,
  :func:`stage_sim.sim.compiled.hit_intensity`);
* tracing a static polygon's outline (an episode's new obstacles): :data:`Trace`
  (:func:`~stage_sim.maps.raster.polygon_edges`, :func:`stage_sim.sim.body_kernels.polygon_outline`).

The numba backend's module is imported on first request only: the numpy path runs without numba.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache, partial
from typing import TYPE_CHECKING, Protocol

import numpy as np

from stage_sim.backend import KERNELS
from stage_sim.maps.raster import polygon_edges
from stage_sim.maps.tiles import CellValues, TileLayer
from stage_sim.sensing.casters import RayCaster, make_caster
from stage_sim.sim.collision import Bodies, CollisionChecker, Contact, GridFrame, place
from stage_sim.sim.drives import DriveGroup, DriveTable
from stage_sim.sim.kinematics import body_velocity
from stage_sim.sim.odometry import integrate_odometry
from stage_sim.sim.ray_groups import SingleCast
from stage_sim.sim.returns import hit_intensity

if TYPE_CHECKING:
    from stage_sim.sim.compiled import FusedResult


class CasterFactory(Protocol):
    """Builds the ray caster of one static layer (the arguments of :func:`~stage_sim.sensing.casters.make_caster`)."""

    def __call__(self, occupied: np.ndarray | TileLayer, resolution: float, origin_xy: tuple[float, float], *,
                 threads: int = 1, blocks: np.ndarray | None = None) -> RayCaster: ...


class ContactFactory(Protocol):
    """Builds the contact checker of a world (the arguments of :class:`~stage_sim.sim.collision.CollisionChecker`)."""

    def __call__(self, bodies: Bodies, grid: GridFrame, layers: list[TileLayer], layer_of_robot: np.ndarray,
                 collides: np.ndarray) -> Contact: ...


Trace = Callable[[np.ndarray], np.ndarray]
"""The cells Stage marks for one closed polygon of vertex cells (M, 2), in its walk's order (K, 2)."""


class Motion(Protocol):
    """Commands to body velocities, and odometry after a step, for all robots at once."""

    def body_velocities(self, commands: np.ndarray, drives: Sequence[DriveGroup], wheelbases: np.ndarray,
                        bounds: np.ndarray) -> np.ndarray:
        """:func:`~stage_sim.sim.kinematics.body_velocity`."""
        ...

    def odometry(self, estimates: np.ndarray, velocities: np.ndarray, errors: np.ndarray, dt: float,
                 uses_odom: np.ndarray, truth: np.ndarray) -> np.ndarray:
        """Odometry after the step: integrated with the errors for robots that ``uses_odom``, else ``truth``."""
        ...

    def place(self, points: np.ndarray, owner: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """:func:`~stage_sim.sim.collision.place` of body points (P, 2), point k with the pose of robot ``owner[k]``
        (the rangers' origins at every sensing step)."""
        ...

    def warm(self, robots: int) -> None:
        """Load what the first step would load (compiled kernels), for ``robots`` robots."""
        ...


class Fused(Protocol):
    """A whole step in few calls, as the roles give it step by step (:meth:`~stage_sim.sim.compiled.FusedStep.step`)."""

    def step(self, commands: np.ndarray, poses: np.ndarray, layers: np.ndarray, layer: int, stalled: np.ndarray,
             estimates: np.ndarray, errors: np.ndarray, uses_odom: np.ndarray, dt: float, cast: bool,
             kernel: Callable[..., int] | None = None, arguments: tuple = ()) -> FusedResult:
        """One step from the robots' commands, every ray cast when ``cast``, none else, its compiled call made by
        ``kernel`` when given: :class:`~stage_sim.sim.compiled.FusedResult`."""
        ...

    def warm(self, poses: np.ndarray) -> None:
        """Load what its steps run (compiled kernels), with the robots at ``poses``."""
        ...

    @property
    def beams(self) -> int:
        """Rays its steps cast (a :class:`FusedBatch` lays every world's scans out by it)."""
        ...

    def world(self) -> object:
        """What its kernels read besides the robots' state: what a :class:`FusedBatch` holds in the world's slot."""
        ...

    def cast_grown(self, tiles: int, layers: np.ndarray, layer: int, poses: np.ndarray, trig: np.ndarray,
                   published: np.ndarray, intensity: np.ndarray) -> None:
        """Grow its robot layer to ``tiles`` and cast every ray again, after a batched step found it too small."""
        ...


class FusedFactory(Protocol):
    """The fused step of a world's contacts and rays (:meth:`~stage_sim.sim.rangers.RangerSensing.single_cast`)
    and its robots' drives on ``threads``, or None where it steps role by role."""

    def __call__(self, collision: Contact, cast: SingleCast | None, threads: int, drives: DriveTable,
                 ) -> Fused | None: ...


def no_fused_step(collision: Contact, cast: SingleCast | None, threads: int, drives: DriveTable) -> None:
    """The numpy reference steps role by role: it is what every fused step must give."""


class FusedBatch(Protocol):
    """Fused steps of several worlds in one call (:class:`~stage_sim.sim.compiled.FusedBatch`)."""

    beams: int  #: rays every world's step casts

    def fits(self, fused: Fused) -> bool:
        """Whether ``fused`` can join the others' call."""
        ...

    def hold(self, slot: int, fused: Fused) -> None:
        """Step ``fused`` (which fits) in ``slot`` from now on."""
        ...

    def step(self, slots: np.ndarray, poses: np.ndarray, layers: np.ndarray, parity: np.ndarray,
             estimates: np.ndarray, velocities: np.ndarray, errors: np.ndarray, dt: float, uses_odom: np.ndarray,
             stalled: np.ndarray) -> FusedResult:
        """The step held in each slot (every ray cast) on the slot's row of the stacked state: new arrays alike."""
        ...


class HitIntensity(Protocol):
    """Writes each ray's return intensity (:func:`~stage_sim.sim.returns.hit_intensity`)."""

    def __call__(self, cell: np.ndarray, hit_robot: np.ndarray, static: CellValues, robot_return: np.ndarray,
                 robots_seen: bool, rays: np.ndarray, out: np.ndarray, threads: int) -> None: ...


class ReferenceMotion:
    """:class:`Motion` on the numpy reference (:mod:`stage_sim.sim.kinematics`, :mod:`stage_sim.sim.odometry`)."""

    @staticmethod
    def body_velocities(commands: np.ndarray, drives: Sequence[DriveGroup], wheelbases: np.ndarray, bounds: np.ndarray,
                        ) -> np.ndarray:
        return body_velocity(commands, drives, wheelbases, bounds)

    @staticmethod
    def odometry(estimates: np.ndarray, velocities: np.ndarray, errors: np.ndarray, dt: float,
                 uses_odom: np.ndarray, truth: np.ndarray) -> np.ndarray:
        return np.where(uses_odom[:, None], integrate_odometry(estimates, velocities, errors, dt), truth)

    @staticmethod
    def place(points: np.ndarray, owner: np.ndarray, poses: np.ndarray) -> np.ndarray:
        return place(points, poses[owner])

    @staticmethod
    def warm(robots: int) -> None:
        """Nothing to load."""


@dataclass(frozen=True)
class Backend:
    """One implementation of every hot path, all giving the numpy reference's answers."""

    name: str  #: its name in :data:`stage_sim.backend.KERNELS`
    caster: CasterFactory
    contact: ContactFactory
    motion: Motion
    hit_intensity: HitIntensity
    fused: FusedFactory
    fused_batch: Callable[[int], FusedBatch] | None  #: on so many threads; None: no fused step, nothing to batch
    trace: Trace


def _numpy() -> Backend:
    return Backend("numpy", partial(make_caster, kernels="numpy"), CollisionChecker, ReferenceMotion(), hit_intensity,
                   no_fused_step, None, polygon_edges)


def _numba() -> Backend:
    from stage_sim.sim import body_kernels, compiled  # imports numba

    return Backend("numba", partial(make_caster, kernels="numba"), compiled.CompiledCollisionChecker,
                   compiled.CompiledMotion(), compiled.hit_intensity, compiled.FusedStep.of, compiled.FusedBatch,
                   body_kernels.polygon_outline)


#: Every backend by name, built on first request.
_BACKENDS = {"numpy": _numpy, "numba": _numba}


@cache
def backend_for(kernels: str) -> Backend:
    """The backend called ``kernels`` (already resolved: :func:`stage_sim.backend.resolve_kernels`)."""
    if kernels not in _BACKENDS:
        raise ValueError(f"kernels must be one of {', '.join(KERNELS)}, not {kernels!r}")
    return _BACKENDS[kernels]()
