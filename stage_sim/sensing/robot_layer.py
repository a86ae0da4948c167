"""Robots as ray obstacles: which rays can reach which robot, then exact cell windows there.

Robots are small and few compared with rays, and the rays of one scan share an origin. So instead
of certifying free space along every ray, the layer works per (scan, robot) pair:

1. **Pairs.** Consecutive rays with the same origin and owner form a *scan*. A robot is a candidate
   for a scan if its cell box is closer to the origin than the scan's longest ray (each ray already
   ends at its static hit) and it is not the scan's own robot.
2. **Rays.** The box subtends an angular interval (< π) seen from the origin; the scan's rays whose
   angle lies in it are found by binary search (angles relative to the scan's first ray, sorted once
   per call). A slab test then keeps the rays that enter the box before their static hit.
3. **Exact windows.** From the box entry, :meth:`RayWindows.cells` follows the traversal, looking up
   every entered cell in the robot-id grid (so any robot's cell counts, not just the box's robot),
   until a hit or the box is left. A ray's answer is its earliest robot hit over all its candidates.

Selection is conservative (margins of ``ANGLE_MARGIN`` and ``BOX_MARGIN``); only the windows decide
hits, with the traversal's own formulas, so results stay exact.
"""

from __future__ import annotations

from collections.abc import Iterator
from itertools import pairwise

import numpy as np

from stage_sim.sensing.ray_windows import EPS, PAD, RayWindows

#: ``hit_robot`` of a cell covered by two or more robots.
SEVERAL_ROBOTS = -2
#: Grid-line crossings per axis resolved per window step: most rays hit a robot's outline within a
#: few cells of entering its box, so the first step is short and the rare long ones take bigger steps.
FIRST_EVENTS, MORE_EVENTS = 4, 8
#: Widening (cells) of a robot's box for the angular selection: rounding of atan2 is ~1e-15 rad.
BOX_MARGIN = 0.01
#: Widening (radians) of each angular interval, on top of ``BOX_MARGIN``.
ANGLE_MARGIN = 1e-7
#: Edges (cells) of the distance bands in which boxes are resolved, nearest first.
BANDS = (0.0, 40.0, 100.0, np.inf)
_TWO_PI = 2.0 * np.pi
#: Key stride between scans: > 2π so that the angle keys of different scans never interleave.
_SCAN_STRIDE = 8.0


def visible_cells(
    cell_rows: np.ndarray, cell_cols: np.ndarray, robot_ids: np.ndarray, shape: tuple[int, int],
    visible: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The (rows, cols, ids) int64 entries that lie on the grid and belong to a visible robot."""
    rows = np.asarray(cell_rows, dtype=np.int64).ravel()
    cols = np.asarray(cell_cols, dtype=np.int64).ravel()
    ids = np.asarray(robot_ids, dtype=np.int64).ravel()
    keep = (rows >= 0) & (rows < shape[0]) & (cols >= 0) & (cols < shape[1]) & (ids >= 0)
    if visible is not None:
        vis = np.asarray(visible, dtype=bool)
        keep &= ids < vis.size
        keep[keep] = vis[ids[keep]]
    return rows[keep], cols[keep], ids[keep]


class RobotLayer:
    """The robots one caster's rays can hit, rebuilt every step (one layer per ray height).

    Each robot covers a set of cells. A ray hits a cell covered by a robot other than its owner; a
    cell covered by two or more robots blocks every ray (they touch there) and is reported as robot
    :data:`SEVERAL_ROBOTS`. Robots not visible at this layer's height (``visible[id]`` false) are left
    out.
    """

    def __init__(self, windows: RayWindows, resolution: float, origin_xy: tuple[float, float]) -> None:
        """A layer over the grid of ``windows`` (a caster's :attr:`~GridRayCaster.windows`), placed like it."""
        self._windows = windows
        self._height, self._width = windows.height, windows.width
        self._resolution = float(resolution)
        self._origin_col = np.array(origin_xy, dtype=np.float64)[:, None]
        self._size_col = np.array([[self._width], [self._height]], dtype=np.float64)
        self._ids = np.full(self._windows.hp * self._windows.wp, -1, dtype=np.int32)
        self._written = np.empty(0, dtype=np.intp)
        self._box = np.empty((4, 0))  # x0, y0, x1, y1 (unpadded cell units) of each robot's cells
        self._box_id = np.empty(0, dtype=np.int64)
        self.active = False

    def update(
        self,
        cell_rows: np.ndarray,
        cell_cols: np.ndarray,
        robot_ids: np.ndarray,
        visible: np.ndarray | None = None,
    ) -> None:
        """Replace the footprints: robot ``robot_ids[i]`` covers cell (``cell_rows[i]``, ``cell_cols[i]``)."""
        rows, cols, ids = visible_cells(cell_rows, cell_cols, robot_ids, (self._height, self._width), visible)
        self._ids[self._written] = -1
        flat = (rows + PAD) * self._windows.wp + (cols + PAD)
        self._ids[flat] = ids
        self._ids[flat[self._ids[flat] != ids]] = SEVERAL_ROBOTS
        self._written = flat
        self.active = flat.size > 0
        if self.active:
            self._boxes(rows, cols, ids)

    def _boxes(self, rows: np.ndarray, cols: np.ndarray, ids: np.ndarray) -> None:
        """Cell box of every robot with cells: [x0, x1] × [y0, y1] in cell units."""
        size = int(ids.max()) + 1
        lo = np.full((2, size), np.iinfo(np.int64).max)
        hi = np.full((2, size), -1)
        np.minimum.at(lo[0], ids, cols)
        np.minimum.at(lo[1], ids, rows)
        np.maximum.at(hi[0], ids, cols)
        np.maximum.at(hi[1], ids, rows)
        present = np.flatnonzero(hi[0] >= 0)
        self._box = np.concatenate([lo[:, present], hi[:, present] + 1]).astype(np.float64)
        self._box_id = present

    def cast_into(self, xy, ang, rmax, owners, t_hit, cell, hit_robot) -> None:
        """Replace each ray's static hit by the first robot cell it enters before it, if any.

        ``t_hit``/``cell`` hold the static pass's answer (time in cells, +inf on a miss); all three
        output arrays are updated in place.
        """
        w = self._windows
        n = ang.shape[0]
        uv = (xy.T - self._origin_col) / self._resolution
        d = np.stack([np.cos(ang), np.sin(ang)]) + 0.0
        inv = 1.0 / d
        # Each ray's limit: just past its static hit (a robot in that very cell wins), else where
        # it leaves the grid or reaches its range.
        exit_edge = np.where(d >= 0, self._size_col, 0.0)
        t_exit = (exit_edge - uv) * inv
        lim = np.fmin(np.fmin(t_exit[0], t_exit[1]), rmax / self._resolution)
        static = np.isfinite(t_hit)
        lim[static] = np.nextafter(t_hit[static], np.inf)
        lim[t_hit <= 0] = 0.0  # the origin cell is occupied: the answer is that cell
        # A ray starting in another robot's cell hits it at once.
        c0 = np.floor(uv)
        inside = ((c0 >= 0) & (c0 < self._size_col)).all(axis=0)
        f0 = ((c0[1] + PAD) * w.wp + (c0[0] + PAD)).astype(np.intp)
        r0 = np.where(inside, self._ids.take(f0, mode="clip"), -1)
        start = np.flatnonzero((r0 != -1) & (r0 != owners))
        if start.size:
            t_hit[start] = 0.0
            cell[start] = w.unpad(f0[start])
            hit_robot[start] = r0[start]
            lim[start] = 0.0
        for ray, t_in, t_out in self._candidates(uv, ang, inv, lim, owners):
            self._resolve(ray, t_in, t_out, uv, d, inv, lim, owners, t_hit, cell, hit_robot, n)

    def _candidates(self, uv, ang, inv, lim, owners) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """(ray, box entry time, box exit time) of the rays that may enter a robot box in time.

        Yields one batch per distance band of the boxes, nearest first, and reads ``lim`` anew for
        each: robots hit in a nearer band hide the farther boxes behind them.
        """
        n = ang.shape[0]
        change = np.empty(n, dtype=bool)
        change[0] = True
        np.not_equal(uv[0, 1:], uv[0, :-1], out=change[1:])
        change[1:] |= uv[1, 1:] != uv[1, :-1]
        change[1:] |= owners[1:] != owners[:-1]
        first = np.flatnonzero(change)
        scan = np.cumsum(change) - 1
        su, sv = uv[0, first, None], uv[1, first, None]
        reach = np.maximum.reduceat(np.where(lim > 0, lim, 0.0), first)[:, None] + 1.0
        x0, y0, x1, y1 = self._box[:, None, :]
        gx = np.maximum(np.maximum(x0 - su, su - x1), 0.0)
        gy = np.maximum(np.maximum(y0 - sv, sv - y1), 0.0)
        near = gx * gx + gy * gy < reach * reach
        near &= self._box_id != owners[first, None]
        ps, pb = np.nonzero(near)
        if ps.size == 0:
            return
        gap = (gx * gx + gy * gy)[ps, pb]
        # Angular interval of each box seen from its scan's origin, relative to the scan's first ray.
        ou, ov = su[ps, 0], sv[ps, 0]
        bx0, by0, bx1, by1 = self._box[:, pb]
        bx0 -= BOX_MARGIN + ou
        by0 -= BOX_MARGIN + ov
        bx1 += BOX_MARGIN - ou
        by1 += BOX_MARGIN - ov
        cx, cy = bx0 + bx1, by0 + by1  # (twice) the direction to the box centre
        lo = np.full(ps.size, np.inf)
        hi = np.full(ps.size, -np.inf)
        for px, py in ((bx0, by0), (bx1, by0), (bx0, by1), (bx1, by1)):
            delta = np.arctan2(cx * py - cy * px, cx * px + cy * py)
            np.minimum(lo, delta, out=lo)
            np.maximum(hi, delta, out=hi)
        start = np.arctan2(cy, cx) + lo - ang[first[ps]] - ANGLE_MARGIN
        np.mod(start, _TWO_PI, out=start)
        end = start + (hi - lo + 2 * ANGLE_MARGIN)
        around = (bx0 < 0) & (bx1 > 0) & (by0 < 0) & (by1 > 0)  # origin in the box: every ray
        start[around], end[around] = -1.0, _TWO_PI + 1.0
        # Sorted angle keys: scan * stride + angle relative to the scan's first ray, in [0, 2π].
        key = np.mod(ang - ang[first[scan]], _TWO_PI)
        key += scan * _SCAN_STRIDE
        order = None
        if np.any(key[1:] < key[:-1]):
            order = np.argsort(key, kind="stable")
            key = key[order]
        base = ps * _SCAN_STRIDE
        wrap = end > _TWO_PI
        a = np.searchsorted(key, base + start, "left")
        b = np.searchsorted(key, base + np.minimum(end, _TWO_PI + 1.0), "right")
        a2 = np.searchsorted(key, base - 1.0, "left")
        b2 = np.where(wrap & ~around, np.searchsorted(key, base + (end - _TWO_PI), "right"), a2)
        for near_edge, far_edge in pairwise(BANDS):
            band = np.flatnonzero((gap >= near_edge * near_edge) & (gap < far_edge * far_edge))
            begin = np.concatenate([a[band], a2[band]])
            count = np.concatenate([b[band] - a[band], b2[band] - a2[band]])
            total = int(count.sum())
            if total == 0:
                continue
            pos = np.repeat(begin - (np.cumsum(count) - count), count) + np.arange(total)
            ray = pos if order is None else order[pos]
            box = np.repeat(np.concatenate([pb[band], pb[band]]), count)
            # Slab test against the box itself (widened by EPS): entry before the ray's limit.
            bx0, by0, bx1, by1 = self._box[:, box]
            iu, iv = inv[0, ray], inv[1, ray]
            tx0 = (bx0 - EPS - uv[0, ray]) * iu
            tx1 = (bx1 + EPS - uv[0, ray]) * iu
            ty0 = (by0 - EPS - uv[1, ray]) * iv
            ty1 = (by1 + EPS - uv[1, ray]) * iv
            t_in = np.fmax(np.fmax(np.fmin(tx0, tx1), np.fmin(ty0, ty1)), 0.0)
            t_out = np.fmin(np.fmax(tx0, tx1), np.fmax(ty0, ty1))
            keep = np.flatnonzero((t_in < lim[ray]) & (t_in <= t_out))
            if keep.size:
                yield ray[keep], t_in[keep], t_out[keep]

    def _resolve(self, ray, t_in, t_out, uv, d, inv, lim, owners, t_hit, cell, hit_robot, n) -> None:
        """Follow each ray through its candidate boxes in order of entry, stopping at the first hit.

        Nearer robots hide farther ones, so in a crowd most rays stop in their first box and the
        farther candidates are never resolved. The windows look up every cell entered, so covering
        each box from its entry to its exit (gaps between boxes hold no robot cell) finds the first
        robot cell exactly.
        """
        w = self._windows
        order = np.lexsort((t_in, ray))
        ray, t_in, t_out = ray[order], t_in[order], t_out[order]
        last = np.empty(ray.size, dtype=bool)  # the ray's last candidate
        last[-1] = True
        np.not_equal(ray[1:], ray[:-1], out=last[:-1])
        rays = np.zeros(n, dtype=bool)
        rays[ray] = True
        sub = np.flatnonzero(rays)
        g = w.constants(uv[:, sub], d[:, sub], inv[:, sub], lim[sub])
        own = owners[sub].astype(np.float64)
        lid = (np.cumsum(rays) - 1)[ray]  # candidate -> row of g
        k = np.flatnonzero(np.concatenate([[True], last[:-1]]))  # each ray's first candidate
        ts = t_in[k]
        events = FIRST_EVENTS
        while k.size:
            li = lid[k]
            hit, tt, flat, rid, t_cov = w.cells(g[:, li], ts, lim[sub[li]], events, own[li], self._ids)
            events = MORE_EVENTS
            robot = np.flatnonzero(hit & (rid != -1) & (rid != own[li]))
            if robot.size:
                out = sub[li[robot]]
                lim[out] = np.nextafter(tt[robot], np.inf)  # farther bands need only look before it
                t_hit[out] = tt[robot]
                cell[out] = w.unpad(flat[robot])
                hit_robot[out] = rid[robot]
            # Box left: go on with the ray's next candidate, from its entry or from here if later.
            left = ~hit & (t_cov >= np.minimum(t_out[k] + EPS, lim[sub[li]]))
            step = left & ~last[k]
            k[step] += 1
            ts = np.where(step, np.maximum(t_cov, t_in[k]), t_cov)
            more = ~hit & (~left | step) & (ts < lim[sub[lid[k]]])
            k, ts = k[more], ts[more]
