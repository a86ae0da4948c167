"""Exact, vectorised laser ray casting on a raster grid (Stage's ``ranger`` model, spec §7.3).

Maths
-----
The world is a raster of square cells of side ``resolution``; ``origin_xy`` is the world position of
the lower-left corner of cell (0, 0) and ``occupied[row, col]`` has row 0 at the bottom. A ray starts
at world point (x, y) with heading θ and maximum length R. All work happens in cell units::

    u = (x − origin_x) / resolution,   v = (y − origin_y) / resolution
    dx = cos θ + 0.0,   dy = sin θ + 0.0          (+ 0.0 turns −0.0 into +0.0)

The ray meets the vertical grid line x = b (b an integer) at t = (b − u) · (1.0 / dx) and the
horizontal line y = b at t = (b − v) · (1.0 / dy), t in cells. An Amanatides–Woo traversal visits the
cells in the order of these crossing times, each computed fresh from its grid line (never by
accumulating increments). On an exact tie (the ray passes through a cell corner) it steps along the
*minor* axis first, the major axis being x when |dx| >= |dy| and y otherwise. The answer is the
crossing time at which the traversal first enters an occupied cell, times ``resolution``; 0 if the
origin cell is occupied; exactly R ("miss") if no occupied cell is entered at a time < R /
resolution. Cells outside the grid are free, so a ray that leaves the grid misses.

Exactness guarantee: :meth:`GridRayCaster.cast` returns, bit for bit, the hit cell and the distance
that this traversal returns (``tests/sensing/test_raycast.py`` holds a plain per-cell reference). The
acceleration below only decides which cells need not be looked at, with safety margins of
``EPS`` cells (≫ float64 rounding, ≪ one cell), and every reported time comes from the formulas above.

How it is fast
--------------
* **Skips.** Per layer, :func:`~stage_sim.sensing.distance_field.quadrant_square_fields` stores, for
  every cell and each diagonal quadrant, the side k of the largest free square with that cell as its
  corner. A ray heading into that quadrant stays inside the square until it has moved k cells along
  one axis, so it jumps to the square's exit (a slab test), minus the margin, in one step.
* **Segments.** Near obstacles (k <= 1) the ray is resolved exactly, a few "segments" at a time: a
  segment is the straight run of cells the ray visits between two crossings of minor-axis grid lines.
  The crossing times fix where each segment starts and ends, and the free-run length of its first cell
  (:func:`~stage_sim.sensing.distance_field.run_lengths`) says whether, and where, it meets an occupied
  cell: one lookup per segment however long it is, which makes rays nearly parallel to walls cheap.
* **Batches.** All rays of all sensors of all robots go through one call; rays are processed in
  cache-sized chunks, finished rays are dropped as they finish, and the few slow rays of every
  chunk are gathered into one final pool so that the Python-level loop runs few times.
* **Robots** (:class:`~stage_sim.sensing.robot_layer.RobotLayer`) are cast after the static pass and
  only look for robot cells entered before the static hit: per (scan, robot) pair, the rays aimed
  at the robot's cell box are resolved there with exact cell windows, nearest robots first.
* The exact kernels live in :mod:`stage_sim.sensing.ray_windows`.

Usage::

    caster = GridRayCaster(occupied, resolution=0.02, origin_xy=(0.0, 0.0))
    result = caster.cast(origins_xy, angles, max_ranges=5.6)       # (N, 2), (N,), float or (N,)
    result.ranges, result.hit_cell, result.hit_robot

    robots = caster.robot_layer()                                   # once per caster; every step:
    robots.update(rows, cols, ids, visible=robot_seen_at_this_height)   # the robots' cells
    result = caster.cast(origins_xy, angles, ranges, owners=ray_robot_ids, robots=robots)

Build one caster per distinct ray height (its occupancy = cells of models whose z band contains the
height and whose ``ranger_return >= 0``); casters cache their fields, so keep them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stage_sim.sensing.distance_field import quadrant_square_fields
from stage_sim.sensing.ray_windows import EPS, MAX_SEGMENTS, PAD, RayWindows
from stage_sim.sensing.robot_layer import RobotLayer

#: Rays per bulk chunk: the working arrays of one chunk stay in the L2 cache.
CHUNK = 8192
#: A chunk hands its remaining rays to the shared tail pool once fewer than this many are left ...
TAIL_SIZE = CHUNK // 16
#: ... or after this many iterations, whichever comes first.
BULK_ITERATIONS = 12
#: Grid-line crossings per axis and step for rays whose origin lies outside the grid.
OUTSIDE_EVENTS = 64
#: Compact the active arrays once fewer than this fraction of them is still alive.
COMPACT_BELOW = 0.75


@dataclass(frozen=True)
class _Mode:
    """Tuning of one phase of the ray loop."""

    segments: int  # segments resolved per exact window (at least) ...
    window_cells: int  # ... or more, up to this many (segment, ray) pairs per window
    near_lines: float  # park a ray for a window when its jump crosses fewer minor grid lines
    park_fraction: float  # run the windows once this fraction of the live rays is parked
    max_iterations: int  # hand the rest to the tail pool after this many iterations (0: never)
    leave_below: int  # ... or once fewer rays than this are alive


BULK = _Mode(3, 0, near_lines=1.0, park_fraction=0.5, max_iterations=BULK_ITERATIONS, leave_below=TAIL_SIZE)
TAIL = _Mode(segments=8, window_cells=4096, near_lines=4.0, park_fraction=0.3, max_iterations=0, leave_below=0)
#: A small batch (one robot's scan) pays per numpy call, not per ray: few, wide windows.
SMALL = _Mode(segments=8, window_cells=2048, near_lines=4.0, park_fraction=0.9, max_iterations=0, leave_below=0)

#: Square side k as a float, less the safety margin on both ends of the jump (indexed by k).
_SIDE_LESS_MARGIN = np.arange(256, dtype=np.float64) - 2 * EPS

# Rows of the skip state matrix.
_T, _OU, _OV, _ADX, _ADY, _IAX, _IAY, _QB, _LIM, _ID, _DMN = range(11)


@dataclass(frozen=True)
class CastResult:
    """Per-ray results, in the order of the input rays."""

    ranges: np.ndarray  #: (N,) float64 metres; exactly the ray's max range on a miss
    hit_cell: np.ndarray  #: (N,) int64 flat index ``row * width + col`` of the hit cell, −1 on a miss
    hit_robot: np.ndarray  #: (N,) int32 id of the robot hit (see :class:`RobotLayer`), −1 otherwise


class GridRayCaster:
    """Exact ray casting against one static occupancy layer (one ray height)."""

    def __init__(self, occupied: np.ndarray, resolution: float, origin_xy: tuple[float, float]) -> None:
        occ = np.asarray(occupied, dtype=bool)
        if occ.ndim != 2 or occ.size == 0:
            raise ValueError("occupied must be a non-empty 2-D array")
        if not resolution > 0:
            raise ValueError("resolution must be positive")
        self.occupied = occ
        self.resolution = float(resolution)
        self.origin_xy = (float(origin_xy[0]), float(origin_xy[1]))
        self.height, self.width = occ.shape
        self._windows = RayWindows(occ)
        self._hp, self._wp = self._windows.hp, self._windows.wp
        self._origin_col = np.array(self.origin_xy)[:, None]
        self._size_col = np.array([[self.width], [self.height]], dtype=np.float64)
        self._squares = quadrant_square_fields(self._windows.padded).ravel()

    kernels = "numpy"

    def robot_layer(self) -> RobotLayer:
        """An empty robot layer for this caster's grid."""
        return RobotLayer(self._windows, self.resolution, self.origin_xy)

    @property
    def windows(self) -> RayWindows:
        """The exact window kernels of this layer (shared with the robot layer)."""
        return self._windows

    # ------------------------------------------------------------------ public API
    def cast(
        self,
        origins_xy: np.ndarray,
        angles: np.ndarray,
        max_ranges: np.ndarray | float,
        owners: np.ndarray | None = None,
        robots: RobotLayer | None = None,
    ) -> CastResult:
        """Cast N rays; ``owners[i]`` is the robot that ray i belongs to (−1: none)."""
        xy = np.asarray(origins_xy, dtype=np.float64).reshape(-1, 2)
        n = xy.shape[0]
        ang = np.broadcast_to(np.asarray(angles, dtype=np.float64), (n,))
        rmax = np.broadcast_to(np.asarray(max_ranges, dtype=np.float64), (n,))
        hit_robot = np.full(n, -1, dtype=np.int32)
        # Divisions by zero (axis-parallel rays) and the infinities they cause are part of the maths.
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            t_hit, cell = self._static_pass(xy, ang, rmax)
            if robots is not None and robots.active:
                own = np.broadcast_to(np.asarray(-1 if owners is None else owners, dtype=np.int64), (n,))
                robots.cast_into(xy, ang, rmax, own, t_hit, cell, hit_robot)
        hit = cell >= 0
        ranges = np.where(hit, t_hit * self.resolution, rmax)
        return CastResult(ranges=ranges, hit_cell=cell, hit_robot=hit_robot)

    # ------------------------------------------------------------------ static pass
    def _static_pass(self, xy: np.ndarray, ang: np.ndarray, rmax: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return (hit time in cells or +inf, hit cell or −1) ignoring robots."""
        n = ang.shape[0]
        t_hit = np.full(n, np.inf)
        cell = np.full(n, -1, dtype=np.int64)
        mode = SMALL if n <= TAIL_SIZE else BULK
        pool: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        for a in range(0, n, CHUNK):
            b = min(a + CHUNK, n)
            prepared = self._prepare(xy[a:b], ang[a:b], rmax[a:b], a, t_hit, cell)
            if prepared is None:
                continue
            s, g, gid = prepared
            left = self._iterate(s, g, gid, t_hit, cell, mode)
            if left.shape[1]:
                loc = left[_ID].astype(np.intp)
                pool.append((left, g.take(loc, axis=1), gid.take(loc)))
        if pool:
            s = np.concatenate([p[0] for p in pool], axis=1)
            g = np.concatenate([p[1] for p in pool], axis=1)
            gid = np.concatenate([p[2] for p in pool])
            s[_ID] = np.arange(gid.size)
            for a in range(0, gid.size, CHUNK):
                self._iterate(s[:, a : a + CHUNK], g, gid, t_hit, cell, TAIL)
        return t_hit, cell

    def _prepare(self, xy, ang, rmax, offset: int, t_hit, cell):
        """Set up one chunk of rays; finish the trivial ones. Return (skip state, window constants, ids)."""
        m = ang.shape[0]
        uv = np.empty((2, m))
        np.subtract(xy.T, self._origin_col, out=uv)
        uv /= self.resolution
        d = np.empty_like(uv)
        np.cos(ang, out=d[0])
        np.sin(ang, out=d[1])
        d += 0.0
        inv = 1.0 / d
        size = self._size_col
        fwd = d >= 0
        c0 = np.floor(uv)
        inside = ((c0 >= 0) & (c0 < size)).all(axis=0)
        flat0 = c0[1] * self.width
        flat0 += c0[0]
        occ0 = inside & self.occupied.ravel().take(flat0.astype(np.intp), mode="clip")
        # Clip to the grid box [0, w] x [0, h]: enter at t_in, leave at t_out (fmin/fmax skip the NaN
        # of a ray lying exactly on a box edge).
        edge = np.where(fwd, 0.0, size)
        t_box = (edge - uv) * inv
        t_in = np.fmax(np.fmax(t_box[0], t_box[1]), 0.0)
        np.subtract(size, edge, out=edge)
        np.subtract(edge, uv, out=t_box)
        t_box *= inv
        lim = np.fmin(t_box[0], t_box[1])
        np.fmin(lim, rmax / self.resolution, out=lim)
        todo = t_in < lim
        if occ0.any():
            hit0 = np.flatnonzero(occ0)
            t_hit[offset + hit0] = 0.0
            cell[offset + hit0] = flat0[hit0].astype(np.int64)
            todo &= ~occ0
        gid = np.arange(offset, offset + m)
        if not inside.all():
            out = np.flatnonzero(todo & ~inside)
            if out.size:
                self._outside_rays(gid[out], uv[:, out], d[:, out], t_in[out], lim[out], t_hit, cell)
            todo &= inside
        g = self._windows.constants(uv, d, inv, lim)
        if todo.all():
            return self._skip_state(uv, d, fwd, t_in, lim, np.arange(m, dtype=np.float64)), g, gid
        ids = np.flatnonzero(todo)
        if ids.size == 0:
            return None
        return self._skip_state(uv[:, ids], d[:, ids], fwd[:, ids], t_in[ids], lim[ids], ids), g, gid

    def _skip_state(self, uv, d, fwd, t0, lim, ids) -> np.ndarray:
        """Stacked skip state, in oriented cells (mirrored so that every ray moves towards +x, +y)."""
        n = t0.size
        s = np.empty((11, n))
        s[_T] = t0
        np.subtract(self._size_col, uv, out=s[_OU : _OV + 1])
        np.copyto(s[_OU : _OV + 1], uv, where=fwd)
        s[_OU : _OV + 1] += PAD - EPS
        np.abs(d, out=s[_ADX : _ADY + 1])
        np.divide(1.0, s[_ADX : _ADY + 1], out=s[_IAX : _IAY + 1])
        np.multiply(fwd[1], -2.0 * self._hp * self._wp, out=s[_QB])
        s[_QB] -= fwd[0] * float(self._hp * self._wp)
        s[_QB] += 3.0 * self._hp * self._wp
        s[_LIM] = lim
        s[_ID] = ids
        np.minimum(s[_ADX], s[_ADY], out=s[_DMN])
        return s

    def _iterate(self, s, g, gid, t_hit, cell, mode: _Mode) -> np.ndarray:
        """Skip / resolve rays of state ``s`` until done; return the state of rays handed back early."""
        wp = float(self._wp)
        squares = self._squares
        n0 = s.shape[1]
        pos_buf, cell_buf = np.empty((2, n0)), np.empty((2, n0))
        flat_buf, tau_buf = np.empty(n0), np.empty(n0)
        idx_buf, k_buf = np.empty(n0, dtype=np.intp), np.empty(n0, dtype=np.uint8)
        near_buf, alive_buf, tmp_buf = np.empty(n0, bool), np.empty(n0, bool), np.empty(n0, bool)
        parked = np.zeros(n0, dtype=bool)
        iteration = 0
        while True:
            iteration += 1
            m = s.shape[1]
            p, c, flat, tau = pos_buf[:, :m], cell_buf[:, :m], flat_buf[:m], tau_buf[:m]
            k, near, alive = k_buf[:m], near_buf[:m], alive_buf[:m]
            # Oriented position, its cell and that cell's free square (side k) ...
            np.multiply(s[_T], s[_ADX : _ADY + 1], out=p)
            p += s[_OU : _OV + 1]
            np.floor(p, out=c)
            np.multiply(c[1], wp, out=flat)
            flat += c[0]
            flat += s[_QB]
            np.copyto(idx_buf[:m], flat, casting="unsafe")
            squares.take(idx_buf[:m], out=k, mode="clip")
            # ... and the time to its exit, less the safety margin.
            c -= p
            c += _SIDE_LESS_MARGIN.take(k)
            c *= s[_IAX : _IAY + 1]
            np.minimum(c[0], c[1], out=tau)
            # Park rays whose jump would not even cross `near_lines` minor grid lines: a window of
            # segments makes more progress there (k <= 1 cannot jump at all).
            np.multiply(tau, s[_DMN], out=flat)
            np.less(flat, mode.near_lines, out=near)
            near |= np.less_equal(k, 1, out=tmp_buf[:m])
            near |= parked
            np.copyto(tau, 0.0, where=near)
            s[_T] += tau
            np.less(s[_T], s[_LIM], out=alive)
            np.logical_and(near, alive, out=parked)
            n_alive = np.count_nonzero(alive)
            n_parked = np.count_nonzero(parked)
            if n_parked and n_parked >= mode.park_fraction * n_alive:
                wi = np.flatnonzero(parked)
                nseg = min(max(mode.segments, mode.window_cells // wi.size), MAX_SEGMENTS)
                done, t_next = self._windows.segments(g, gid, s[_ID, wi].astype(np.intp), s[_T, wi], nseg, t_hit, cell)
                s[_T, wi] = t_next
                dead = wi[done]
                s[_LIM, dead] = -1.0
                alive[dead] = False
                n_alive -= dead.size
                parked[:] = False
            if n_alive == 0:
                return s[:, :0]
            if (mode.max_iterations and iteration >= mode.max_iterations) or n_alive <= mode.leave_below:
                return s.take(np.flatnonzero(alive), axis=1)
            if n_alive < COMPACT_BELOW * m:
                keep = np.flatnonzero(alive)
                s = s.take(keep, axis=1)
                parked = parked[keep]

    def _outside_rays(self, ids, uv, d, t_in, lim, t_hit, cell) -> None:
        """Rays whose origin lies outside the grid: skip to the grid, then exact cell windows."""
        g = self._windows.constants(uv, d, 1.0 / d, lim)
        t = t_in.copy()
        todo = np.arange(ids.size)
        while todo.size:
            hit, th, flat, _, t_cov = self._windows.cells(g[:, todo], t[todo], lim[todo], OUTSIDE_EVENTS, clip=True)
            done = hit | (t_cov >= lim[todo])
            if hit.any():
                hi = todo[hit]
                t_hit[ids[hi]] = th[hit]
                cell[ids[hi]] = self._windows.unpad(flat[hit])
            t[todo] = t_cov
            todo = todo[~done]
