"""Stage 4.3's ray walk (``World::Raytrace`` in libstage/world.cc), ported statement by statement.

The test oracle for stage_sim's casters, which walk the same way (:mod:`stage_sim.sensing.stage_walk`)
but skip free space and handle robots: this port visits every cell, plainly. Run on stage_sim's static
raster it also reproduces Stage's recorded scans, if that raster holds exactly Stage's cells. What it
does (and what differs from the distance to where the true ray enters the first occupied cell):

* the walk is Cohen's integer line: ``ax = (int)|dx|``, ``ay = (int)|dy|`` cells to go, error term
  ``ay − ax`` to start with, so the cells visited are those of a line through the *centre* of the start
  cell, not through the ray's origin;
* the range is the distance travelled along the major axis, ``|globx − startx| / |cos a|``, where globx
  moves by whole cells from the origin (a fraction of a cell short or long of the hit cell's entry);
* regions of 32 × 32 cells holding no block are jumped over; after a jump globx (or globy) sits on a
  region border, one cell *beyond* it when moving towards −x (−y), so from there on a ray moving left
  (down) reports the far side of the cell it hits.
"""

from __future__ import annotations

import math

import numba
import numpy as np

REGION = 32  #: cells per region side (Stage's RBITS = 5)


def stage_ray_ranges(
    layer: np.ndarray, offset: np.ndarray, block_cells: np.ndarray, origin: tuple[float, float], yaw: float,
    fov: float, samples: int, range_max: float, resolution: float,
) -> np.ndarray:
    """Ranges of one Stage scan. ``layer[row, col]`` is the grid of cells a ray stops at, its cell (0, 0)
    being Stage's cell ``offset`` (col, row); ``block_cells`` (K, 2) are the Stage cells of every block in
    the world (the scanning robot's own included), which decide which regions are empty."""
    regions, region_low = region_grid(block_cells)
    ppm = 1.0 / resolution
    start = fov / 2.0 - yaw
    ranges = np.empty(samples)
    for s in range(samples):
        angle = (s * fov / (samples - 1)) - start if samples > 1 else yaw
        ranges[s] = raytrace(layer, int(offset[0]), int(offset[1]), regions, int(region_low[0]),
                             int(region_low[1]), origin[0], origin[1], angle, range_max, ppm)[0]
    return ranges


def region_grid(block_cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(regions holding a block, region (col, row) of regions[0, 0]) of Stage cells ``block_cells`` (K, 2)."""
    region_low = np.floor_divide(block_cells.min(axis=0), REGION)
    region_high = np.floor_divide(block_cells.max(axis=0), REGION)
    regions = np.zeros((region_high[1] - region_low[1] + 1, region_high[0] - region_low[0] + 1), dtype=np.bool_)
    index = np.floor_divide(block_cells, REGION) - region_low
    regions[index[:, 1], index[:, 0]] = True
    return regions, region_low


@numba.njit(cache=True)
def raytrace(layer, col0, row0, regions, rcol0, rrow0, x, y, a, range_max, ppm, robots=None, owner=-1):
    """(range, flat cell of ``layer`` or -1) of one ray from world point (x, y) at angle a.

    ``robots`` (optional, ``layer``'s shape): a robot id per cell or -1; a robot's cell blocks the rays of
    every other ``owner``."""
    globx = x * ppm
    globy = y * ppm
    startx, starty = globx, globy
    angle = 1e-12 if a == 0.0 else a
    sina, cosa = math.sin(angle), math.cos(angle)
    tana = sina / cosa
    dx, dy = ppm * range_max * cosa, ppm * range_max * sina
    sx = 1 if dx > 0 else (-1 if dx < 0 else 0)
    sy = 1 if dy > 0 else (-1 if dy < 0 else 0)
    ax, ay = int(abs(dx)), int(abs(dy))
    bx, by = 2 * ax, 2 * ay
    exy = ay - ax
    n = ax + ay
    xjumpx, xjumpy = sx * REGION, sx * REGION * tana
    yjumpx, yjumpy = sy * REGION / tana, sy * REGION
    xjumpdist = abs(xjumpx) + abs(xjumpy)
    yjumpdist = abs(yjumpx) + abs(yjumpy)
    xcrossx = xcrossy = ycrossx = ycrossy = dist_x = dist_y = 0.0
    calculate_crossings = True
    while n > 0:
        ix, iy = int(globx), int(globy)  # C's truncating conversion, as Stage's GETCELL/GETREG get it
        rr, rc = (iy >> 5) - rrow0, (ix >> 5) - rcol0
        if 0 <= rr < regions.shape[0] and 0 <= rc < regions.shape[1] and regions[rr, rc]:
            calculate_crossings = True
            cx, cy = ix & 31, iy & 31
            gx, gy = ix, iy
            while 0 <= cx < REGION and 0 <= cy < REGION and n > 0:
                r, c = gy - row0, gx - col0
                if 0 <= r < layer.shape[0] and 0 <= c < layer.shape[1] and (
                        layer[r, c] or (robots is not None and robots[r, c] != -1 and robots[r, c] != owner)):
                    if ax > ay:
                        return abs((globx - startx) / cosa) / ppm, r * layer.shape[1] + c
                    return abs((globy - starty) / sina) / ppm, r * layer.shape[1] + c
                if exy < 0:
                    globx += sx
                    exy += by
                    cx += sx
                    gx += sx
                else:
                    globy += sy
                    exy -= bx
                    cy += sy
                    gy += sy
                n -= 1
        else:
            if calculate_crossings:
                calculate_crossings = False
                ix, iy = int(globx), int(globy)
                regionx = float(int(ix / REGION) * REGION)
                regiony = float(int(iy / REGION) * REGION)
                if globx < 0 and ix % REGION != 0:
                    regionx -= REGION
                if globy < 0 and iy % REGION != 0:
                    regiony -= REGION
                xdx = regionx - globx - 1.0 if sx < 0 else regionx + REGION - globx
                xdy = xdx * tana
                ydy = regiony - globy - 1.0 if sy < 0 else regiony + REGION - globy
                ydx = ydy / tana
                xcrossx, xcrossy = globx + xdx, globy + xdy
                ycrossx, ycrossy = globx + ydx, globy + ydy
                dist_x = abs(xdx) + abs(xdy)
                dist_y = abs(ydx) + abs(ydy)
            if dist_x < dist_y:
                globx, globy = xcrossx, xcrossy
                n = int(n - dist_x)
                xcrossx += xjumpx
                xcrossy += xjumpy
                dist_y -= dist_x
                dist_x = xjumpdist
            else:
                globx, globy = ycrossx, ycrossy
                n = int(n - dist_y)
                ycrossx += yjumpx
                ycrossy += yjumpy
                dist_x -= dist_y
                dist_y = yjumpdist
    return range_max, -1
