"""``make_caster``: the ray caster of the chosen implementation (see :mod:`stage_sim.backend`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from stage_sim.backend import resolve_kernels
from stage_sim.maps.tiles import TileLayer
from stage_sim.sensing.raycast import GridRayCaster

if TYPE_CHECKING:
    from stage_sim.sensing.fast_caster import NumbaRayCaster


def make_caster(
    occupied: np.ndarray | TileLayer, resolution: float, origin_xy: tuple[float, float], kernels: str | None = None,
    threads: int = 1, blocks: np.ndarray | None = None,
) -> GridRayCaster | NumbaRayCaster:
    """A ray caster for one static layer, of the implementation :func:`resolve_kernels` picks.

    ``occupied``: the layer in tiles (:meth:`~stage_sim.maps.raster.StaticRaster.sensing_tiles`: its grid knows
    the regions holding a static block at any height, which Stage's walk does not skip), or a dense (H, W)
    grid with ``blocks``, the dense cells of every static block at any height (default: ``occupied``)."""
    if resolve_kernels(kernels) == "numba":
        from stage_sim.sensing.fast_caster import NumbaRayCaster

        return NumbaRayCaster(occupied, resolution, origin_xy, threads, blocks)
    return GridRayCaster(occupied, resolution, origin_xy, blocks)
