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
calls for both, and the region grid. The walk itself runs in :mod:`stage_sim.sensing.traversal` (numba)
and :mod:`stage_sim.sensing.raycast` (numpy), which must agree bit for bit. Both skip free space with
free squares without changing an answer: every cell skipped is free, and the reported distance depends
only on how many steps were taken along each axis since the last region jump (``base + count``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Cells per region side (Stage's ``RBITS = 5``).
REGION_BITS = 5
REGION = 1 << REGION_BITS
#: Stage turns a beam at exactly angle 0 into this angle (a zero sine would divide by zero).
ZERO_ANGLE = 1e-12


@dataclass(frozen=True)
class WalkGrid:
    """Where a caster's grid lies in Stage's world cells, and which of its regions hold blocks."""

    col0: int  #: world cell column of the grid's column 0
    row0: int  #: world cell row of the grid's row 0
    rcol0: int  #: region column of the region grid's column 0
    rrow0: int
    static_regions: np.ndarray  #: (R, C) bool: regions holding a static block cell

    @classmethod
    def build(cls, blocks: np.ndarray, resolution: float, origin_xy: tuple[float, float]) -> WalkGrid:
        """The grid of ``blocks`` (cells holding any block) placed at ``origin_xy`` (snapped to a cell)."""
        col0 = round(origin_xy[0] / resolution)
        row0 = round(origin_xy[1] / resolution)
        h, w = blocks.shape
        rcol0, rrow0 = col0 >> REGION_BITS, row0 >> REGION_BITS
        shape = (((row0 + h - 1) >> REGION_BITS) - rrow0 + 1, ((col0 + w - 1) >> REGION_BITS) - rcol0 + 1)
        grid = cls(col0, row0, rcol0, rrow0, np.zeros(shape, dtype=bool))
        rows, cols = np.nonzero(blocks)
        grid.static_regions[grid.region_index(rows, cols)] = True
        return grid

    def region_index(self, rows: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(region rows, region cols) in the region grid of grid cells (rows, cols)."""
        return (((rows + self.row0) >> REGION_BITS) - self.rrow0, ((cols + self.col0) >> REGION_BITS) - self.rcol0)

    def with_cells(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """The region grid with the regions of grid cells (rows, cols) marked too (robots' blocks)."""
        regions = self.static_regions.copy()
        regions[self.region_index(rows, cols)] = True
        return regions


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
    ang = np.broadcast_to(np.asarray(angles, dtype=np.float64), (n,))
    rmax = np.broadcast_to(np.asarray(max_ranges, dtype=np.float64), (n,))
    own = np.ascontiguousarray(np.broadcast_to(np.asarray(-1 if owners is None else owners, dtype=np.int64), (n,)))
    return xy, ang, rmax, own


def beam_cos_sin(angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of the beam angles, an angle of exactly 0 turned into :data:`ZERO_ANGLE` as Stage does."""
    angle = np.where(angles == 0.0, ZERO_ANGLE, angles)
    return np.cos(angle), np.sin(angle)


def finish_ranges(walked: np.ndarray, max_ranges: np.ndarray) -> np.ndarray:
    """Ranges in metres: the walk's distance, exactly the maximum range on a miss (``walked`` = inf)."""
    return np.where(np.isfinite(walked), walked, max_ranges)
