"""The ray caster's interface, which both implementations satisfy, and ``make_caster`` to build one.

:class:`~stage_sim.sensing.raycast.GridRayCaster` (the numpy reference) and
:class:`~stage_sim.sensing.fast_caster.NumbaRayCaster` (compiled) answer every call alike, bit for bit
(``tests/sensing``). Which one a simulation uses is decided with its other kernels in
:func:`stage_sim.sim.backends.backend_for`; this layer, below the simulation, builds casters by name itself.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from stage_sim.backend import resolve_kernels
from stage_sim.maps.tiles import TileLayer
from stage_sim.sensing.raycast import CastResult
from stage_sim.sensing.robot_layer import RobotLayer


@runtime_checkable
class RayCaster(Protocol):
    """Stage's ray walk against one static occupancy layer (one ray height)."""

    resolution: float
    origin_xy: tuple[float, float]

    def robot_layer(self) -> RobotLayer:
        """An empty robot layer for this caster's grid (the robots the rays see, updated every step)."""
        ...

    def cast(self, origins_xy: np.ndarray, angles: np.ndarray, max_ranges: np.ndarray | float,
             owners: np.ndarray | None = None, robots: RobotLayer | None = None) -> CastResult:
        """Cast N rays; ``owners[i]`` is the robot that ray i belongs to (−1: none)."""
        ...

    def cast_into(self, origins: np.ndarray, origin_of: np.ndarray, heading: np.ndarray, local: np.ndarray,
                  rmax: np.ndarray, owners: np.ndarray, robots: RobotLayer | None, out_at: np.ndarray,
                  out: np.ndarray, jitter: np.ndarray = ..., trig: tuple[np.ndarray, np.ndarray, np.ndarray] = ...,
                  ) -> tuple[np.ndarray, np.ndarray]:
        """The simulation's batched cast: ranges written into ``out``; returns (hit cell, hit robot) per ray."""
        ...


def make_caster(
    occupied: np.ndarray | TileLayer, resolution: float, origin_xy: tuple[float, float], kernels: str | None = None,
    threads: int = 1, blocks: np.ndarray | None = None,
) -> RayCaster:
    """A ray caster for one static layer, of the implementation :func:`~stage_sim.backend.resolve_kernels` picks.

    ``occupied``: the layer in tiles (:meth:`~stage_sim.maps.raster.StaticRaster.sensing_tiles`: its grid knows
    the regions holding a static block at any height, which Stage's walk does not skip), or a dense (H, W)
    grid with ``blocks``, the dense cells of every static block at any height (default: ``occupied``);
    ``threads``: the compiled caster's (the reference runs on one)."""
    if resolve_kernels(kernels) == "numba":
        from stage_sim.sensing.fast_caster import NumbaRayCaster

        return NumbaRayCaster(occupied, resolution, origin_xy, threads, blocks)
    from stage_sim.sensing.raycast import GridRayCaster

    return GridRayCaster(occupied, resolution, origin_xy, blocks)
