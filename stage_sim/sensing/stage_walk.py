"""Stage's ray walk (``World::Raytrace``, libstage/world.cc): what both ray casters compute, and why.

Stage does not return the distance to where the true ray enters the first occupied cell. It walks an
integer line, and the scans it publishes are what that walk reports, so stage_sim walks the same line:

* the walk is Cohen's integer line from the cell holding the origin, ``ax = (int)|dx|``, ``ay = (int)|dy|``
  cells to go (dx, dy: the range in cells along each axis), error term ``ay − ax`` to start with, a step
  along x while the error is negative (``+= 2·ay``), else along y (``−= 2·ax``); ``ax + ay`` steps in all.
  The cells visited are those of a line through the *centre* of the start cell, not through the origin;
* a cell blocks the walk when the walk stands in it (the start cell included: range 0); the range is the
  distance travelled along the major axis, ``|globx − startx| / |cos a|`` in cells (x major when
  ``ax > ay``), where ``globx`` moves by whole cells from ``startx = x / resolution``: up to a cell short
  of, or beyond, the true entry;
* the world is cut into regions of 32 × 32 cells (aligned on world cell 0); a region holding no block at
  all (of any model, at any height) is jumped over to where the line meets its border, ``globx`` set to
  that real crossing. Towards −x (−y) the crossing is placed one cell *beyond* the border, so from there
  on the walk reports the far side of the cell it hits. The error term is not reset by a jump.

A ray that meets no blocking cell within its ``ax + ay`` steps reads exactly its maximum range. The
cells are Stage's cells: world cell ``(int)(x / resolution)`` (C's truncation), the grid's cell (0, 0)
being world cell ``round(origin / resolution)``. Robots are cells too: a cell covered by a robot other
than the ray's own blocks it, as a static cell does.

This module holds what both implementations share: the per-ray constants, computed by the same numpy
calls for both, and the static layer in tiles of regions (:mod:`stage_sim.maps.tiles`). The walk itself
runs in :mod:`stage_sim.sensing.traversal` (numba) and :mod:`stage_sim.sensing.raycast` (numpy), which
must agree bit for bit. Both cross free cells in groups without changing an answer (the numpy walk by
free squares, the compiled one by runs of its line tested against bit masks): every cell crossed is free,
and the reported distance depends only on how many steps were taken along each axis since the last region
jump (``base + count``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stage_sim.maps.tiles import TILE, TILE_BITS, TileGrid, TileLayer

#: Cells per region side (Stage's ``RBITS = 5``): the world's tiles are its regions.
REGION_BITS = TILE_BITS
REGION = TILE
#: Robot occupancy blocks inside a region, 2**BLOCK cells a side: the numpy walk crosses robot-free blocks
#: at once.
BLOCK = 3
#: Stage turns a beam at exactly angle 0 into this angle (a zero sine would divide by zero).
ZERO_ANGLE = 1e-12


def static_layer(
    occupied: np.ndarray | TileLayer, resolution: float, origin_xy: tuple[float, float],
    blocks: np.ndarray | None = None,
) -> TileLayer:
    """A caster's static layer: ``occupied`` itself when it is already in tiles, else the tiles of a dense
    (H, W) grid placed at ``origin_xy`` whose regions hold blocks where ``blocks | occupied`` has a cell."""
    if isinstance(occupied, TileLayer):
        return occupied
    occ = np.asarray(occupied, dtype=bool)
    if occ.ndim != 2 or occ.size == 0:
        raise ValueError("occupied must be a non-empty 2-D array")
    every = occ if blocks is None else np.asarray(blocks, dtype=bool) | occ
    grid = TileGrid.build(occ.shape, resolution, origin_xy, np.flatnonzero(every))
    return TileLayer.from_cells(grid, np.flatnonzero(occ))


@dataclass(frozen=True)
class WalkRays:
    """Per-ray constants of the walk, as Stage computes them (``startx = x · ppm``, ``dx = ppm · R · cos a``)."""

    startx: np.ndarray
    starty: np.ndarray
    cosa: np.ndarray
    sina: np.ndarray
    tana: np.ndarray
    dx: np.ndarray
    dy: np.ndarray
    ppm: float

    @classmethod
    def build(cls, xy: np.ndarray, angles: np.ndarray, max_ranges: np.ndarray, resolution: float) -> WalkRays:
        """Constants of rays from world points ``xy`` (N, 2) at ``angles`` reaching ``max_ranges`` metres."""
        ppm = 1.0 / resolution
        cosa, sina = beam_cos_sin(angles)
        reach = ppm * max_ranges
        return cls(np.ascontiguousarray(xy[:, 0] * ppm), np.ascontiguousarray(xy[:, 1] * ppm), cosa, sina,
                   sina / cosa, reach * cosa, reach * sina, ppm)


def ray_arguments(
    origins_xy: np.ndarray, angles: np.ndarray, max_ranges: np.ndarray | float, owners: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A cast's arguments as both casters take them: (N, 2) origins, then angles, ranges and owners
    broadcast to N (owners −1 when not given), so that the two kernels read identical inputs."""
    xy = np.asarray(origins_xy, dtype=np.float64).reshape(-1, 2)
    n = xy.shape[0]
    return xy, _per_ray(angles, n, np.float64), _per_ray(max_ranges, n, np.float64), _per_ray(
        -1 if owners is None else owners, n, np.int64)


def _per_ray(value: np.ndarray | float, n: int, dtype: type) -> np.ndarray:
    """``value`` as a contiguous array of ``n`` entries of ``dtype``: as it is when it already is one (the
    simulation's own calls, once per step, where broadcasting would cost more than the cast of a scan)."""
    if isinstance(value, np.ndarray) and value.dtype == dtype and value.shape == (n,) and value.flags.c_contiguous:
        return value
    return np.ascontiguousarray(np.broadcast_to(np.asarray(value, dtype=dtype), (n,)))


def beam_cos_sin(angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of the beam angles, an angle of exactly 0 turned into :data:`ZERO_ANGLE` as Stage does.

    Computed by the C library's ``cos`` and ``sin`` (Python's ``math``), as Stage computes them and as the
    compiled walk does (numba calls the same functions), so both casters start every ray alike whatever
    SIMD routines numpy's ufuncs pick on a machine."""
    angle = np.where(np.asarray(angles, dtype=np.float64) == 0.0, ZERO_ANGLE, angles).ravel()
    return (np.fromiter(map(math.cos, angle.tolist()), np.float64, angle.size),
            np.fromiter(map(math.sin, angle.tolist()), np.float64, angle.size))


def finish_ranges(walked: np.ndarray, max_ranges: np.ndarray) -> np.ndarray:
    """Ranges in metres: the walk's distance, exactly the maximum range on a miss (``walked`` = inf)."""
    return np.where(np.isfinite(walked), walked, max_ranges)
