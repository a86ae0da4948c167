"""``make_caster``: the ray caster of the chosen implementation (see :mod:`stage_sim.sensing.kernels`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from stage_sim.sensing.kernels import resolve_kernels
from stage_sim.sensing.raycast import GridRayCaster

if TYPE_CHECKING:
    from stage_sim.sensing.fast_caster import NumbaRayCaster


def make_caster(
    occupied: np.ndarray, resolution: float, origin_xy: tuple[float, float], kernels: str | None = None,
    threads: int = 1, blocks: np.ndarray | None = None,
) -> GridRayCaster | NumbaRayCaster:
    """A ray caster for one static layer, of the implementation :func:`resolve_kernels` picks.

    ``blocks``: the cells of every static block at any height (Stage skips regions without one)."""
    if resolve_kernels(kernels) == "numba":
        from stage_sim.sensing.fast_caster import NumbaRayCaster

        return NumbaRayCaster(occupied, resolution, origin_xy, threads, blocks)
    return GridRayCaster(occupied, resolution, origin_xy, blocks)
