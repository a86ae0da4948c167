"""Vectorised laser ray casting on a raster grid (Stage's ``ranger`` model, spec §7.3): the numpy reference.

Every ray follows Stage's walk (:mod:`stage_sim.sensing.stage_walk`: what is walked and reported, and why
Stage's walk rather than the true ray), and the answer is bit for bit what the compiled kernel
(:mod:`stage_sim.sensing.traversal`) returns: the same per-ray constants, the same integer walk, the same
float expressions for the region crossings and the reported distance.

Grid: square cells of side ``resolution``; ``occupied[row, col]`` has row 0 at the bottom, and the grid's
cell (0, 0) is Stage's world cell ``round(origin_xy / resolution)``. Cells outside the grid are free.

How it is fast: all rays advance together, one *action* per ray and round: a region test (and, for an
empty region, Stage's jump to its border), or one cell of the walk. Free space inside a region holding
blocks is crossed in one action: the walk may take any number of steps that keep it inside the largest
free square ahead of its cell within the region's tile
(:func:`~stage_sim.sensing.distance_field.tile_square_fields`), the square of robot-free blocks
(:class:`~stage_sim.sensing.robot_layer.RobotLayer`) and the region, and :func:`walk_prefix` says where the
walk stands after them. Finished rays leave the arrays. The world is read through its tiles
(:mod:`stage_sim.maps.tiles`): 4 KB of free squares per static tile, nothing for empty space.

Usage::

    caster = GridRayCaster(occupied, resolution=0.02, origin_xy=(0.0, 0.0))
    result = caster.cast(origins_xy, angles, max_ranges=5.6)       # (N, 2), (N,), float or (N,)
    result.ranges, result.hit_cell, result.hit_robot

    robots = caster.robot_layer()                                   # once per caster; every step:
    robots.update(rows, cols, ids, visible=robot_seen_at_this_height)   # the robots' cells
    result = caster.cast(origins_xy, angles, ranges, owners=ray_robot_ids, robots=robots)

Build one caster per distinct ray height (its occupancy = cells of models whose z band contains the
height and whose ``ranger_return >= 0``: :meth:`~stage_sim.maps.raster.StaticRaster.sensing_tiles`, or a
dense grid); casters cache their fields, so keep them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stage_sim.maps.tiles import TileGrid, TileLayer
from stage_sim.sensing.distance_field import SQUARE_CAP, tile_square_fields
from stage_sim.sensing.robot_layer import RobotLayer
from stage_sim.sensing.stage_walk import (
    REGION,
    REGION_BITS,
    WalkRays,
    finish_ranges,
    ray_arguments,
    static_layer,
)

# Rows of the integer state (_TILE: static tile of the region the walk is in, _RTILE: its robot tile).
_ID, _KX, _KY, _E, _N, _SX, _SY, _BX, _BY, _Q, _IN, _CX, _CY, _R, _C, _CALC, _OWN, _XMAJ, _TILE, _RTILE = range(20)
_NONE = np.zeros(0)  # no jitter, no trigonometry cache
# Rows of the float state.
(_BASEX, _BASEY, _STX, _STY, _COS, _SIN, _TAN, _XCX, _XCY, _YCX, _YCY, _DSX, _DSY, _XJX, _XJY, _YJX, _YJY, _XJD,
 _YJD) = range(19)


@dataclass(frozen=True)
class CastResult:
    """Per-ray results, in the order of the input rays."""

    ranges: np.ndarray  #: (N,) float64 metres; exactly the ray's max range on a miss
    hit_cell: np.ndarray  #: (N,) int64 flat index ``row * width + col`` of the hit cell, −1 on a miss
    hit_robot: np.ndarray  #: (N,) int32 id of the robot hit (see :class:`RobotLayer`), −1 otherwise


def walk_prefix(e0, bx, by, mx, my, n):
    """(i, j) arrays: the most x-steps (<= mx) and y-steps (<= my), i + j <= n, the walk takes from error e0.

    Where the walk stands after a free stretch, in closed form (integer arithmetic only).
    """
    safe_bx = np.maximum(bx, 1)
    room = my * bx - e0
    i = np.where(room <= 0, 0, np.where(by > 0, np.minimum(mx, (room - 1) // np.maximum(by, 1) + 1), mx))
    i = np.where(i > 0, np.minimum(i, np.maximum(0, (n * bx + by - e0 - 1) // np.maximum(bx + by, 1))), i)
    j = np.minimum(np.minimum((e0 + i * by) // safe_bx + 1, my), n - i)
    zero_bx = bx == 0
    return np.where(zero_bx, 0, i), np.where(zero_bx, np.minimum(my, n), j)


class GridRayCaster:
    """Stage's ray walk against one static occupancy layer (one ray height).

    ``occupied``: the layer in tiles, or a dense (H, W) grid; ``blocks`` (dense only): cells holding a
    block of any model at any height (they decide Stage's empty regions), default ``occupied``."""

    def __init__(self, occupied: np.ndarray | TileLayer, resolution: float, origin_xy: tuple[float, float],
                 blocks: np.ndarray | None = None) -> None:
        if not resolution > 0:
            raise ValueError("resolution must be positive")
        layer = static_layer(occupied, resolution, origin_xy, blocks)
        self.resolution = float(resolution)
        self.origin_xy = (float(origin_xy[0]), float(origin_xy[1]))
        self.height, self.width = layer.grid.shape
        self._grid = layer.grid
        self._tile_of_slot = layer.tile_of_slot
        self._squares = free_squares(layer)

    def robot_layer(self) -> RobotLayer:
        """An empty robot layer for this caster's grid."""
        return RobotLayer(self._grid)

    def cast(
        self,
        origins_xy: np.ndarray,
        angles: np.ndarray,
        max_ranges: np.ndarray | float,
        owners: np.ndarray | None = None,
        robots: RobotLayer | None = None,
    ) -> CastResult:
        """Cast N rays; ``owners[i]`` is the robot that ray i belongs to (−1: none)."""
        xy, ang, rmax, own = ray_arguments(origins_xy, angles, max_ranges, owners)
        n = xy.shape[0]
        rays = WalkRays.build(xy, ang, rmax, self.resolution)
        walked = np.full(n, np.inf)
        cell = np.full(n, -1, dtype=np.int64)
        hit_robot = np.full(n, -1, dtype=np.int32)
        active = robots if robots is not None and robots.active else None
        regions = robots.regions if robots is not None else None
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            self._walk(rays, own, regions, active, walked, cell, hit_robot)
        return CastResult(ranges=finish_ranges(walked, rmax), hit_cell=cell, hit_robot=hit_robot)

    def cast_into(
        self, origins: np.ndarray, origin_of: np.ndarray, heading: np.ndarray, local: np.ndarray, rmax: np.ndarray,
        owners: np.ndarray, robots: RobotLayer | None, out_at: np.ndarray, out: np.ndarray,
        jitter: np.ndarray = _NONE, trig: tuple[np.ndarray, np.ndarray, np.ndarray] = (_NONE, _NONE, _NONE),
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`cast` as the simulation calls it (the arguments of
        :meth:`~stage_sim.sensing.fast_caster.NumbaRayCaster.cast_into`): ray i from ``origins[origin_of[i]]``
        at angle ``heading[origin_of[i]] + local[i]`` (plus ``jitter[out_at[i]]`` when given), its range written
        to ``out[out_at[i]]``. ``trig`` (the compiled caster's cache of cosines and sines) is not needed here.
        Returns (hit cell, hit robot) per ray."""
        angles = heading[origin_of] + local
        if jitter.size:
            angles = angles + jitter[out_at]
        result = self.cast(origins[origin_of], angles, rmax, owners=owners, robots=robots)
        out[out_at] = result.ranges
        return result.hit_cell, result.hit_robot

    # ------------------------------------------------------------------ the walk, all rays at once
    def _walk(self, rays: WalkRays, own, regions, robots, walked, cell, hit_robot) -> None:
        si, sf = _start_state(rays, own)
        g = self._grid
        w = self.width
        ppm = rays.ppm
        while si.shape[1]:
            # Out of steps: a miss. Left the region: look at the region again.
            live = si[_N] > 0
            if not live.all():
                si, sf = si[:, live], sf[:, live]
            si[_IN] &= (si[_CX] >= 0) & (si[_CX] < REGION) & (si[_CY] >= 0) & (si[_CY] < REGION)
            outer = np.flatnonzero(si[_IN] == 0)
            if outer.size:
                self._region_step(si, sf, outer, regions, g)
            inner = np.flatnonzero(si[_IN] == 1)
            done = np.zeros(si.shape[1], dtype=bool)
            if inner.size:
                self._cell_step(si, sf, inner, robots, w, ppm, walked, cell, hit_robot, done)
            if done.any():
                keep = ~done
                si, sf = si[:, keep], sf[:, keep]

    def _region_step(self, si, sf, rows, regions: np.ndarray | None, g: TileGrid) -> None:
        """Stage's outer loop for rays ``rows``: enter a region holding blocks (static or robot cells, the
        latter in ``regions``), or jump over an empty one."""
        globx = sf[_BASEX, rows] + si[_KX, rows]
        globy = sf[_BASEY, rows] + si[_KY, rows]
        ix, iy = globx.astype(np.int64), globy.astype(np.int64)
        rr, rc = (iy >> REGION_BITS) - g.rrow0, (ix >> REGION_BITS) - g.rcol0
        rh, rw = g.slots.shape
        inside = (rr >= 0) & (rr < rh) & (rc >= 0) & (rc < rw)
        slot = np.full(rows.size, -1, dtype=np.int64)
        slot[inside] = g.slots[rr[inside], rc[inside]]
        robot_tile = np.full(rows.size, -1, dtype=np.int64)
        if regions is not None:
            robot_tile[inside] = regions[rr[inside], rc[inside]]
        full = (slot >= 0) | (robot_tile != -1)
        enter = rows[full]
        static = enter[slot[full] >= 0]
        si[_TILE, enter] = -1
        si[_TILE, static] = self._tile_of_slot[slot[slot >= 0]]
        si[_RTILE, enter] = robot_tile[full]
        si[_CALC, enter] = 1
        si[_IN, enter] = 1
        si[_CX, enter], si[_CY, enter] = ix[full] & (REGION - 1), iy[full] & (REGION - 1)
        si[_R, enter], si[_C, enter] = iy[full] - g.row0, ix[full] - g.col0
        empty = ~full
        jump = rows[empty]
        if not jump.size:
            return
        ix, iy, globx, globy = ix[empty], iy[empty], globx[empty], globy[empty]
        calc = si[_CALC, jump] == 1
        if calc.any():
            c = jump[calc]
            ix, iy, globx, globy = ix[calc], iy[calc], globx[calc], globy[calc]
            si[_CALC, c] = 0
            regionx = (np.trunc(ix / REGION).astype(np.int64) * REGION).astype(np.float64)
            regiony = (np.trunc(iy / REGION).astype(np.int64) * REGION).astype(np.float64)
            regionx -= np.where((globx < 0) & (ix % REGION != 0), REGION, 0)
            regiony -= np.where((globy < 0) & (iy % REGION != 0), REGION, 0)
            xdx = np.where(si[_SX, c] < 0, regionx - globx - 1.0, regionx + REGION - globx)
            xdy = xdx * sf[_TAN, c]
            ydy = np.where(si[_SY, c] < 0, regiony - globy - 1.0, regiony + REGION - globy)
            ydx = ydy / sf[_TAN, c]
            sf[_XCX, c], sf[_XCY, c] = globx + xdx, globy + xdy
            sf[_YCX, c], sf[_YCY, c] = globx + ydx, globy + ydy
            sf[_DSX, c] = np.abs(xdx) + np.abs(xdy)
            sf[_DSY, c] = np.abs(ydx) + np.abs(ydy)
        si[_KX, jump] = si[_KY, jump] = 0
        dist_x, dist_y = sf[_DSX, jump], sf[_DSY, jump]
        by_x = dist_x < dist_y
        xs, ys = jump[by_x], jump[~by_x]
        sf[_BASEX, xs], sf[_BASEY, xs] = sf[_XCX, xs], sf[_XCY, xs]
        si[_N, xs] = (si[_N, xs] - sf[_DSX, xs]).astype(np.int64)
        sf[_XCX, xs] += sf[_XJX, xs]
        sf[_XCY, xs] += sf[_XJY, xs]
        sf[_DSY, xs] -= sf[_DSX, xs]
        sf[_DSX, xs] = sf[_XJD, xs]
        sf[_BASEX, ys], sf[_BASEY, ys] = sf[_YCX, ys], sf[_YCY, ys]
        si[_N, ys] = (si[_N, ys] - sf[_DSY, ys]).astype(np.int64)
        sf[_YCX, ys] += sf[_YJX, ys]
        sf[_YCY, ys] += sf[_YJY, ys]
        sf[_DSX, ys] -= sf[_DSY, ys]
        sf[_DSY, ys] = sf[_YJD, ys]

    def _cell_step(self, si, sf, rows, robots, w, ppm, walked, cell, hit_robot, done) -> None:
        """One cell of Stage's inner loop for rays ``rows``: a hit, a jump through free space, or one step."""
        r, c = si[_R, rows], si[_C, rows]
        sx, sy, q = si[_SX, rows], si[_SY, rows], si[_Q, rows]
        cx, cy, tile = si[_CX, rows], si[_CY, rows], si[_TILE, rows]
        # a region with no static tile at this height is free up to its border
        k = np.minimum(np.where(sx > 0, REGION - cx, cx + 1), np.where(sy > 0, REGION - cy, cy + 1))
        static = tile >= 0
        k[static] = self._squares[tile[static], q[static], cy[static], cx[static]]
        kbx = np.full(rows.size, SQUARE_CAP, dtype=np.int64)
        kby = kbx.copy()
        rid = np.full(rows.size, -1, dtype=np.int64)
        if robots is not None:
            g = np.flatnonzero(si[_RTILE, rows] >= 0)
            rid[g], kbx[g], kby[g], plain = robots.look(si[_RTILE, rows[g]], cy[g], cx[g], sx[g], sy[g], q[g],
                                                        si[_OWN, rows[g]])
            k[g[plain]] = np.minimum(k[g[plain]], 1)
        hit = (rid != -1) | (k == 0)
        if hit.any():
            hr = rows[hit]
            globx = sf[_BASEX, hr] + si[_KX, hr]
            globy = sf[_BASEY, hr] + si[_KY, hr]
            ids = si[_ID, hr]
            walked[ids] = np.where(si[_XMAJ, hr] == 1, np.abs((globx - sf[_STX, hr]) / sf[_COS, hr]) / ppm,
                                   np.abs((globy - sf[_STY, hr]) / sf[_SIN, hr]) / ppm)
            cell[ids] = r[hit] * w + c[hit]
            hit_robot[ids] = rid[hit]
            done[hr] = True
        go = ~hit
        rows, k, kbx, kby, sx, sy = rows[go], k[go], kbx[go], kby[go], sx[go], sy[go]
        e, bx, by, n = si[_E, rows], si[_BX, rows], si[_BY, rows], si[_N, rows]
        mx = np.minimum(k, kbx) - 1  # both squares end at the region's border
        my = np.minimum(k, kby) - 1
        i, j = walk_prefix(e, bx, by, mx, my, n)
        jump = (k > 1) & (i + j > 0)
        step_x = ~jump & (e < 0)
        step_y = ~jump & ~step_x
        i = np.where(jump, i, step_x)
        j = np.where(jump, j, step_y)
        si[_KX, rows] += i * sx
        si[_CX, rows] += i * sx
        si[_C, rows] += i * sx
        si[_KY, rows] += j * sy
        si[_CY, rows] += j * sy
        si[_R, rows] += j * sy
        si[_E, rows] += i * by - j * bx
        si[_N, rows] -= i + j


def free_squares(layer: TileLayer) -> np.ndarray:
    """The layer's free squares (:func:`~stage_sim.sensing.distance_field.tile_square_fields`, 4 KB a tile),
    computed the first time only and kept with the layer (casters of heights that see the same cells share
    them)."""
    if "squares" not in layer.derived:
        layer.derived["squares"] = tile_square_fields(layer.occupied)
    return layer.derived["squares"]


def _start_state(rays: WalkRays, own: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(integer state, float state) of every ray before its first action, as Stage sets it up."""
    n = own.size
    si = np.zeros((20, n), dtype=np.int64)
    sf = np.zeros((19, n))
    sx = np.where(rays.dx > 0, 1, np.where(rays.dx < 0, -1, 0))
    sy = np.where(rays.dy > 0, 1, np.where(rays.dy < 0, -1, 0))
    ax, ay = np.abs(rays.dx).astype(np.int64), np.abs(rays.dy).astype(np.int64)
    si[_ID] = np.arange(n)
    si[_E] = ay - ax
    si[_N] = ax + ay
    si[_SX], si[_SY] = sx, sy
    si[_BX], si[_BY] = 2 * ax, 2 * ay
    si[_Q] = (sx < 0) + 2 * (sy < 0)
    si[_CALC] = 1
    si[_OWN] = own
    si[_XMAJ] = ax > ay
    sf[_BASEX], sf[_BASEY] = rays.startx, rays.starty
    sf[_STX], sf[_STY] = rays.startx, rays.starty
    sf[_COS], sf[_SIN], sf[_TAN] = rays.cosa, rays.sina, rays.tana
    sf[_XJX] = (sx * REGION).astype(np.float64)
    sf[_XJY] = (sx * REGION) * rays.tana
    sf[_YJX] = (sy * REGION) / rays.tana
    sf[_YJY] = (sy * REGION).astype(np.float64)
    sf[_XJD] = np.abs(sf[_XJX]) + np.abs(sf[_XJY])
    sf[_YJD] = np.abs(sf[_YJX]) + np.abs(sf[_YJY])
    return si, sf

