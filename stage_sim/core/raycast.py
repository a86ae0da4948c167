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
that this traversal returns (``tests/core/test_raycast.py`` holds a plain per-cell reference). The
acceleration below only decides which cells need not be looked at, with safety margins of
``EPS`` cells (≫ float64 rounding, ≪ one cell), and every reported time comes from the formulas above.

How it is fast
--------------
* **Skips.** Per layer, :func:`~stage_sim.core.distance_field.quadrant_square_fields` stores, for
  every cell and each diagonal quadrant, the side k of the largest free square with that cell as its
  corner. A ray heading into that quadrant stays inside the square until it has moved k cells along
  one axis, so it jumps to the square's exit (a slab test), minus the margin, in one step.
* **Segments.** Near obstacles (k <= 1) the ray is resolved exactly, a few "segments" at a time: a
  segment is the straight run of cells the ray visits between two crossings of minor-axis grid lines.
  The crossing times fix where each segment starts and ends, and the free-run length of its first cell
  (:func:`~stage_sim.core.distance_field.run_lengths`) says whether, and where, it meets an occupied
  cell: one lookup per segment however long it is, which makes rays nearly parallel to walls cheap.
* **Batches.** All rays of all sensors of all robots go through one call; rays are processed in
  cache-sized chunks, finished rays are dropped as they finish, and the few slow rays of every
  chunk are gathered into one final pool so that the Python-level loop runs few times.
* **Robots** (:class:`RobotLayer`) are cast in a second pass that only looks for robot cells entered
  before the static hit: free space is certified per step at the level of 8 × 8-cell blocks (an
  owner-aware pyramid near the ray's own robot, quadrant squares of robot-free blocks elsewhere)
  and resolved exactly, cell by cell, near other robots.

Usage::

    caster = GridRayCaster(occupied, resolution=0.02, origin_xy=(0.0, 0.0))
    result = caster.cast(origins_xy, angles, max_ranges=5.6)       # (N, 2), (N,), float or (N,)
    result.ranges, result.hit_cell, result.hit_robot

    robots = RobotLayer(caster)                                     # once per caster; every step:
    rows, cols, ids = polygon_cells(footprints_xy, 0.02, (0.0, 0.0), occupied.shape)   # (R, M, 2)
    robots.update(rows, cols, ids, visible=robot_seen_at_this_height)
    result = caster.cast(origins_xy, angles, ranges, owners=ray_robot_ids, robots=robots)

Build one caster per distinct ray height (its occupancy = cells of models whose z band contains the
height and whose ``ranger_return >= 0``); casters cache their fields, so keep them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stage_sim.core.distance_field import (
    NO_ROBOT_HI,
    NO_ROBOT_LO,
    block_summary,
    neighbourhood_summary,
    quadrant_square_fields,
    run_lengths,
)

#: Free border (cells) around every stored field, so positions on the grid's edge index safely.
PAD = 1
#: Positional safety margin in cells: far above float64 rounding of cell coordinates (~1e-12 for
#: grids up to 1e4 cells), far below a cell, so a certified jump never reaches an unchecked cell.
EPS = 1e-6
#: Rays per bulk chunk: the working arrays of one chunk stay in the L2 cache.
CHUNK = 8192
#: A chunk hands its remaining rays to the shared tail pool once fewer than this many are left ...
TAIL_SIZE = CHUNK // 16
#: ... or after this many iterations, whichever comes first.
BULK_ITERATIONS = 12
#: Upper bound of segments per window (bounds the memory of tiny, long-range batches).
MAX_SEGMENTS = 256
#: Grid-line crossings per axis and step for the general cell windows (robots, outside origins).
CELL_EVENTS = 6
OUTSIDE_EVENTS = 64
#: Side (cells) of the finest robot block of :class:`RobotLayer`'s certificate pyramid.
ROBOT_BLOCK = 8
#: Rays per chunk of the robot pass (its loop runs longer, so fewer, larger chunks pay off).
ROBOT_CHUNK = 4 * CHUNK
#: ``hit_robot`` of a cell covered by two or more robots.
SEVERAL_ROBOTS = -2
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

# Rows of the per-ray constant matrix used by the exact windows (major axis a, minor axis b).
(_PA, _PB, _DA, _DB, _IA, _IB, _SA, _SB, _A0, _B0, _CAO, _PAB, _PBB, _STA, _STB, _BASE, _CBN, _YMAJ, _REFF) = range(19)
_NG = 19
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
        padded = np.zeros((self.height + 2 * PAD, self.width + 2 * PAD), dtype=bool)
        padded[PAD:-PAD, PAD:-PAD] = occ
        self._hp, self._wp = padded.shape
        self._origin_col = np.array(self.origin_xy)[:, None]
        self._index = np.arange(ROBOT_CHUNK)
        self._ramps = {j: np.arange(j, dtype=np.float64)[:, None] for j in range(MAX_SEGMENTS + 2)}
        self._size_col = np.array([[self.width], [self.height]], dtype=np.float64)
        self._occ_flat = padded.ravel()
        self._squares = quadrant_square_fields(padded).ravel()
        self._runs = run_lengths(padded).ravel()

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
                robots.cast_into(self, xy, ang, rmax, own, t_hit, cell, hit_robot)
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
        g = self._window_constants(uv, d, inv, lim)
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
        size = np.array([[self.width], [self.height]], dtype=np.float64)
        s[_T] = t0
        np.subtract(size, uv, out=s[_OU : _OV + 1])
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

    def _window_constants(self, uv, d, inv, lim) -> np.ndarray:
        """Per-ray constants of the exact segment windows, in (major a, minor b) axis terms."""
        hw = float(self._hp * self._wp)
        wp = float(self._wp)
        xmaj = np.abs(d[0]) >= np.abs(d[1])
        g = np.empty((_NG, lim.size))
        np.copyto(g[_PA : _PB + 1], uv[::-1])
        np.copyto(g[_PA : _PB + 1], uv, where=xmaj)
        np.copyto(g[_DA : _DB + 1], d[::-1])
        np.copyto(g[_DA : _DB + 1], d, where=xmaj)
        np.copyto(g[_IA : _IB + 1], inv[::-1])
        np.copyto(g[_IA : _IB + 1], inv, where=xmaj)
        neg = g[_DA : _DB + 1] < 0
        np.multiply(neg, -2.0, out=g[_SA : _SB + 1])
        g[_SA : _SB + 1] += 1.0
        np.floor(g[_PA : _PB + 1], out=g[_A0 : _B0 + 1])
        np.subtract(1.0, neg[0], out=g[_CAO])  # 1 if the major grid line ahead of cell m is m + 1
        np.multiply(g[_SA : _SB + 1], -EPS, out=g[_PAB : _PBB + 1])
        g[_PAB : _PBB + 1] += g[_PA : _PB + 1]
        # Run-length arrays +x, -x, +y, -y: the run of the cell (major m, minor line gamma) sits at
        # base + m * sta + gamma * stb.
        np.subtract(wp, xmaj * (wp - 1.0), out=g[_STA])
        np.subtract(wp + 1.0, g[_STA], out=g[_STB])
        np.multiply(xmaj, -2.0 * hw, out=g[_BASE])
        g[_BASE] += neg[0] * hw + (2.0 * hw + PAD * (wp + 1.0))
        g[_BASE] -= neg[1] * g[_STB]
        g[_CBN] = neg[1]  # the grid line a ray enters minor cell n through is n + (sb < 0)
        np.logical_not(xmaj, out=g[_YMAJ], casting="unsafe")
        g[_REFF] = lim
        return g

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
                done, t_next = self._segment_window(g, gid, s[_ID, wi].astype(np.intp), s[_T, wi], nseg, t_hit, cell)
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

    def _segment_window(self, g, gid, ids, ts, segments: int, t_hit, cell) -> tuple[np.ndarray, np.ndarray]:
        """Resolve rays ``ids`` exactly over the next ``segments`` segments from time ``ts``.

        Segment c of a ray is the straight run of cells it visits after crossing c minor grid lines
        (c = 0: from the origin). Writes hits into ``t_hit``/``cell``; returns (finished mask, time to
        continue from; 0 if finished). Arrays are (segment, ray) so per-ray constants broadcast on rows.
        """
        pa, pb, da, db, ia, ib, sa, sb, a0, b0, cao, pab, pbb, sta, stb, base, cbn, ymaj, reff = g.take(ids, axis=1)
        m = ids.size
        nseg = segments
        # Minor cell at ts (from a position at/behind, never behind the origin) and the grid line that
        # opened its segment (for the origin's segment: the line behind the origin).
        n0 = pbb + ts * db
        np.floor(n0, out=n0)
        n0 *= sb
        np.maximum(n0, sb * b0, out=n0)
        n0 *= sb
        n0 += cbn
        gam = self._ramps[nseg + 1] * sb
        gam += n0  # grid line opening each segment ...
        tau = gam - pb
        tau *= ib  # ... and the time the ray crosses it
        # mm = major cell index when the ray crosses gam: a candidate from a position at/behind, then
        # one exact comparison with the time the ray leaves that cell (minor steps first on ties,
        # hence the strict <). The first two rows may sit at the origin: never behind it.
        mm = tau * da
        mm += pab
        np.floor(mm, out=mm)
        head = mm[:2]
        head *= sa
        np.fmax(head, sa * a0, out=head)  # fmax: a ray lying on its grid line crosses it at 0 * inf
        head *= sa
        tk = mm + cao
        tk -= pa
        tk *= ia
        mm += np.multiply(tk < tau, sa, out=tk)
        # Segment j covers major cells mm[j] .. mm[j + 1]: one free-run lookup at its first cell.
        flat = mm[:-1] * sta
        flat += base
        tmp = gam[:-1] * stb
        flat += tmp
        run = self._runs.take(flat.astype(np.intp), mode="clip")
        np.subtract(mm[1:], mm[:-1], out=tmp)
        tmp *= sa
        hit = run <= tmp
        if nseg <= 4:
            first = np.full(m, nseg, dtype=np.intp)
            for j in range(nseg - 1, -1, -1):
                np.copyto(first, j, where=hit[j])
        else:
            first = np.where(hit, self._ramps[nseg], nseg).min(axis=0).astype(np.intp)
        has = first < nseg
        fi = np.minimum(first, nseg - 1, out=first)
        fi *= m
        fi += self._arange(m)
        rf = run.ravel().take(fi)
        mh = mm.ravel().take(fi)
        mh += sa * rf
        th = mh - cao
        th += 1.0  # the grid line the ray enters major cell mh through ...
        th -= pa
        th *= ia  # ... and when
        np.copyto(th, tau.ravel().take(fi), where=rf == 0)
        t_cov = tau[nseg]
        done = t_cov >= reff
        done |= has
        has &= th < reff
        hs = np.flatnonzero(has)
        if hs.size:
            minor = gam.ravel().take(fi[hs]) - (sb[hs] < 0)
            major = mh[hs]
            ym = ymaj[hs] > 0
            out = gid[ids[hs]]
            t_hit[out] = th[hs]
            cell[out] = (np.where(ym, major, minor) * self.width + np.where(ym, minor, major)).astype(np.int64)
        t_cov[done] = 0.0
        return done, t_cov

    def _cell_window(self, g, ts, lim, events: int, owner=None, robot_ids=None, clip=False):
        """Resolve rays exactly over their next ``events`` grid-line crossings of each axis.

        The general (slower) counterpart of the segment window: every cell entered is looked up, so
        it also handles robot cells and rays starting outside the grid. Per axis the crossings come
        in time order; the cell entered at a major crossing has the minor index reached by then
        (minor crossings at the same time count: minor steps first) and the cell entered at a minor
        crossing the major index reached strictly before. Returns (hit, time, padded flat cell,
        robot id or -1, time covered). Hits at times >= ``lim`` are ignored.
        """
        pa, pb, da, db, ia, ib, sa, sb, a0, b0, cao, pab, pbb, sta, _, _, cbn, _, _ = g
        # Events at times >= lim are never reported, so their (possibly off-grid) cells may be garbage.
        hp, wp = float(self._hp), float(self._wp)
        ramp = self._ramps[events]
        cbo = 1.0 - cbn
        # First grid line of each axis at/after the position at ts, never behind the origin's.
        first_a = np.floor(pab + ts * da)
        first_a *= sa
        np.maximum(first_a, sa * a0, out=first_a)
        first_a *= sa
        first_a += cao
        first_b = np.floor(pbb + ts * db)
        first_b *= sb
        np.maximum(first_b, sb * b0, out=first_b)
        first_b *= sb
        first_b += cbo
        # Major crossings: time, then the minor cell reached by then (candidate + one comparison).
        line_a = ramp * sa
        line_a += first_a
        t_a = (line_a - pa) * ia
        n_a = np.floor(pbb + t_a * db)
        n_a += np.multiply(~((n_a + cbo - pb) * ib > t_a), sb)  # NaN: lying on that grid line
        m_a = line_a + cao  # cell entered: the line's own index moving up, the one below moving down
        m_a -= 1.0
        # Minor crossings: time, then the major cell reached strictly before (never behind origin).
        line_b = ramp * sb
        line_b += first_b
        t_b = (line_b - pb) * ib
        m_b = np.floor(pab + t_b * da)
        head = m_b[:1]
        head *= sa
        np.fmax(head, sa * a0, out=head)
        head *= sa
        m_b += np.multiply((m_b + cao - pa) * ia < t_b, sa)
        n_b = line_b + cbo
        n_b -= 1.0
        stb = (wp + 1.0) - sta
        times, hits, flats, rids = [], [], [], []
        for mj, nj, tj in ((m_a, n_a, t_a), (m_b, n_b, t_b)):
            flat = mj * sta
            flat += nj * stb
            flat += PAD * (wp + 1.0)
            if clip:  # origins outside the grid: cells outside it are free
                col = np.where(sta == 1.0, mj, nj) + PAD
                row = np.where(sta == 1.0, nj, mj) + PAD
                flat[(col < 0) | (col >= wp) | (row < 0) | (row >= hp)] = -1.0
            flat = flat.astype(np.intp)
            occ = self._occ_flat.take(flat, mode="clip")
            if clip:
                occ &= flat >= 0
            rid = None
            if robot_ids is not None:
                rid = robot_ids.take(flat, mode="clip")
                occ |= (rid != -1) & (rid != owner)
            occ &= tj < lim
            first = np.where(occ, ramp, float(events)).min(axis=0).astype(np.intp)
            has = first < events
            pick = np.minimum(first, events - 1) * tj.shape[1] + self._arange(tj.shape[1])
            times.append(np.where(has, tj.ravel().take(pick), np.inf))
            hits.append(has)
            flats.append(flat.ravel().take(pick))
            rids.append(rid.ravel().take(pick) if rid is not None else None)
        use_b = times[1] <= times[0]  # minor crossing first on a tie
        t_hit = np.where(use_b, times[1], times[0])
        t_cov = np.minimum(t_a[-1], t_b[-1])
        hit = (hits[0] | hits[1]) & (t_hit <= t_cov)
        flat = np.where(use_b, flats[1], flats[0])
        rid = np.full(ts.shape, -1, dtype=np.int64) if robot_ids is None else np.where(use_b, rids[1], rids[0])
        return hit, t_hit, flat, rid, t_cov

    def _outside_rays(self, ids, uv, d, t_in, lim, t_hit, cell) -> None:
        """Rays whose origin lies outside the grid: skip to the grid, then exact cell windows."""
        g = self._window_constants(uv, d, 1.0 / d, lim)
        t = t_in.copy()
        todo = np.arange(ids.size)
        while todo.size:
            hit, th, flat, _, t_cov = self._cell_window(g[:, todo], t[todo], lim[todo], OUTSIDE_EVENTS, clip=True)
            done = hit | (t_cov >= lim[todo])
            if hit.any():
                hi = todo[hit]
                t_hit[ids[hi]] = th[hit]
                cell[ids[hi]] = self._unpad(flat[hit])
            t[todo] = t_cov
            todo = todo[~done]

    def _arange(self, n: int) -> np.ndarray:
        """0, 1, ..., n − 1 (cached for the usual sizes)."""
        return self._index[:n] if n <= self._index.size else np.arange(n)

    def _unpad(self, flat: np.ndarray) -> np.ndarray:
        """Padded flat index -> flat index ``row * width + col`` of the unpadded grid."""
        row, col = np.divmod(flat, self._wp)
        return ((row - PAD) * self.width + (col - PAD)).astype(np.int64)


class RobotLayer:
    """The robots one caster's rays can hit, rebuilt every step (one layer per ray height).

    Each robot covers a set of cells (see :func:`polygon_cells`). A ray hits a cell covered by a
    robot other than its owner; a cell covered by two or more robots blocks every ray (they touch
    there) and is reported as robot :data:`SEVERAL_ROBOTS`. Robots not visible at this layer's
    height (``visible[id]`` false) are left out.

    Free space is certified with a pyramid of robot blocks (``ROBOT_BLOCK`` cells, doubling per
    level): if the 3 × 3 blocks around a cell's block at some level hold no robot, the nearest robot
    cell is more than one block away, so a ray may jump that far. Each block also remembers the one
    robot its neighbourhood holds, if only one, and how far it is certainly free of every *other*
    robot, so a ray leaving its own robot is not slowed down by it.
    """

    def __init__(self, caster: GridRayCaster) -> None:
        self._caster = caster
        hp, wp = caster._hp, caster._wp
        self._ids = np.full(hp * wp, -1, dtype=np.int32)
        self._written = np.empty(0, dtype=np.intp)
        self._hb, self._wb = -(-hp // ROBOT_BLOCK), -(-wp // ROBOT_BLOCK)
        self._k_any = self._k_own = self._uid = np.empty(0)
        self.active = False

    def update(
        self,
        cell_rows: np.ndarray,
        cell_cols: np.ndarray,
        robot_ids: np.ndarray,
        visible: np.ndarray | None = None,
    ) -> None:
        """Replace the footprints: robot ``robot_ids[i]`` covers cell (``cell_rows[i]``, ``cell_cols[i]``)."""
        c = self._caster
        rows = np.asarray(cell_rows, dtype=np.int64).ravel()
        cols = np.asarray(cell_cols, dtype=np.int64).ravel()
        ids = np.asarray(robot_ids, dtype=np.int64).ravel()
        keep = (rows >= 0) & (rows < c.height) & (cols >= 0) & (cols < c.width) & (ids >= 0)
        if visible is not None:
            vis = np.asarray(visible, dtype=bool)
            keep &= ids < vis.size
            keep[keep] = vis[ids[keep]]
        rows, cols, ids = rows[keep] + PAD, cols[keep] + PAD, ids[keep].astype(np.int32)
        self._ids[self._written] = -1
        flat = rows * c._wp + cols
        self._ids[flat] = ids
        self._ids[flat[self._ids[flat] != ids]] = SEVERAL_ROBOTS
        self._written = flat
        self.active = flat.size > 0
        if self.active:
            self._certify(rows // ROBOT_BLOCK * self._wb + cols // ROBOT_BLOCK, ids)

    def _certify(self, blocks: np.ndarray, ids: np.ndarray) -> None:
        """Per level-0 block: jump length clear of all robots, and of all robots but ``uid``."""
        bid = np.full(self._hb * self._wb, -1, dtype=np.int32)
        bid[blocks] = ids
        several = blocks[bid[blocks] != ids]
        lo = np.where(bid < 0, NO_ROBOT_LO, bid).reshape(self._hb, self._wb)
        hi = np.where(bid < 0, NO_ROBOT_HI, bid).reshape(self._hb, self._wb)
        lo.ravel()[several] = -2
        hi.ravel()[several] = NO_ROBOT_LO
        levels = [(lo, hi)]
        while levels[-1][0].size > 1:
            levels.append(block_summary(*levels[-1]))
        k_any = k_own = uid = None
        for level in range(len(levels) - 1, -1, -1):
            nlo, nhi = neighbourhood_summary(*levels[level])
            jump = float(ROBOT_BLOCK * 2**level + 1)
            empty = nlo == NO_ROBOT_LO
            single = nlo == nhi
            if k_any is None:
                k_any = np.where(empty, jump, 0.0)
                uid = np.where(single, nlo, -1)
                k_own = np.where(empty | single, jump, 0.0)
                continue
            h, w = nlo.shape
            k_any, k_own, uid = (np.repeat(np.repeat(a, 2, axis=0), 2, axis=1)[:h, :w] for a in (k_any, k_own, uid))
            np.maximum(k_any, np.where(empty, jump, 0.0), out=k_any)
            same = single & (uid == nlo)
            k_own = np.where(empty, np.maximum(k_own, k_any), np.where(same, k_own, np.where(single, jump, 0.0)))
            uid = np.where(empty, uid, np.where(single, nlo, -1))
            np.copyto(k_own, k_any, where=uid < 0)
        self._k_any, self._k_own, self._uid = k_any.ravel(), k_own.ravel(), uid.ravel()
        # Far from a ray's own robot, robots behind the ray do not matter: quadrant squares of
        # robot-free blocks (as for the static layer) give long jumps between robots.
        self._squares = quadrant_square_fields((bid >= 0).reshape(self._hb, self._wb)).ravel()

    def certificate(self, rows, cols, flip_x, flip_y, owner) -> np.ndarray:
        """Square side k (cells) certainly free of robots other than ``owner``, ahead of padded cells.

        ``flip_x`` / ``flip_y`` (0 or 1) say that the ray moves towards −x / −y.
        """
        bx = np.floor(cols / ROBOT_BLOCK)
        by = np.floor(rows / ROBOT_BLOCK)
        b = (by * self._wb + bx).astype(np.intp)
        k = self._k_any.take(b, mode="clip")
        np.copyto(k, self._k_own.take(b, mode="clip"), where=self._uid.take(b, mode="clip") == owner)
        # Oriented (mirrored) block and cell coordinates for the quadrant squares.
        span_x, span_y = self._wb * ROBOT_BLOCK - 1.0, self._hb * ROBOT_BLOCK - 1.0
        ox = cols + flip_x * (span_x - 2 * cols)
        oy = rows + flip_y * (span_y - 2 * rows)
        obx = bx + flip_x * (self._wb - 1.0 - 2 * bx)
        oby = by + flip_y * (self._hb - 1.0 - 2 * by)
        q = (2 * flip_y + flip_x) * float(self._hb * self._wb)
        side = self._squares.take((q + oby * self._wb + obx).astype(np.intp), mode="clip")
        reach = np.minimum((obx + side) * ROBOT_BLOCK - ox, (oby + side) * ROBOT_BLOCK - oy)
        return np.maximum(k, reach, out=k)

    def cast_into(self, caster, xy, ang, rmax, owners, t_hit, cell, hit_robot) -> None:
        """Second pass: look for robot cells entered before each ray's static hit."""
        n = ang.shape[0]
        for a in range(0, n, ROBOT_CHUNK):
            b = min(a + ROBOT_CHUNK, n)
            self._cast_chunk(caster, xy[a:b], ang[a:b], rmax[a:b], owners[a:b], a, t_hit, cell, hit_robot)

    def _cast_chunk(self, c, xy, ang, rmax, owners, offset, t_hit, cell, hit_robot) -> None:
        m = ang.shape[0]
        uv = np.empty((2, m))
        np.subtract(xy.T, c._origin_col, out=uv)
        uv /= c.resolution
        d = np.empty_like(uv)
        np.cos(ang, out=d[0])
        np.sin(ang, out=d[1])
        d += 0.0
        inv = 1.0 / d
        fwd = d >= 0
        edge = np.where(fwd, 0.0, c._size_col)
        t_box = (edge - uv) * inv
        t_in = np.fmax(np.fmax(t_box[0], t_box[1]), 0.0)
        t_box = (c._size_col - edge - uv) * inv
        lim = np.fmin(np.fmin(t_box[0], t_box[1]), rmax / c.resolution)
        th = t_hit[offset : offset + m]
        np.copyto(lim, np.nextafter(th, np.inf), where=np.isfinite(th))
        # A ray starting in another robot's cell hits it at once.
        c0 = np.floor(uv)
        inside = ((c0 >= 0) & (c0 < c._size_col)).all(axis=0) & (th > 0)
        f0 = ((c0[1] + PAD) * c._wp + (c0[0] + PAD)).astype(np.intp)
        r0 = np.where(inside, self._ids.take(f0, mode="clip"), -1)
        start = inside & (r0 != -1) & (r0 != owners)
        if start.any():
            i = np.flatnonzero(start)
            t_hit[offset + i] = 0.0
            cell[offset + i] = c._unpad(f0[i])
            hit_robot[offset + i] = r0[i]
        todo = np.flatnonzero((t_in < lim) & ~start & (th > 0))
        if todo.size == 0:
            return
        g = c._window_constants(uv[:, todo], d[:, todo], inv[:, todo], lim[todo])
        s = c._skip_state(uv[:, todo], d[:, todo], fwd[:, todo], t_in[todo], lim[todo], np.arange(todo.size))
        own = owners[todo].astype(np.float64)
        wp, hp = float(c._wp), float(c._hp)
        hw = hp * wp
        while s.shape[1]:
            p = s[_OU : _OV + 1] + s[_T] * s[_ADX : _ADY + 1]
            cc = np.floor(p)
            # Oriented cell -> padded grid cell (undo the mirroring of rays moving left / down).
            q = s[_QB] / hw
            flip_y = q >= 2
            flip_x = q - 2 * flip_y
            col = cc[0] + flip_x * (wp - 1 - 2 * cc[0])
            row = cc[1] + flip_y * (hp - 1 - 2 * cc[1])
            ids = s[_ID].astype(np.intp)
            k = self.certificate(row, col, flip_x, flip_y, own[ids])
            cc -= p
            cc += k - 2 * EPS
            cc *= s[_IAX : _IAY + 1]
            tau = np.minimum(cc[0], cc[1])
            near = k <= 1
            tau[near] = 0.0
            s[_T] += tau
            alive = s[_T] < s[_LIM]
            wi = np.flatnonzero(near & alive)
            if wi.size:
                gi = ids[wi]
                hit, tt, flat, rid, t_cov = c._cell_window(
                    g[:, gi], s[_T, wi], s[_LIM, wi], CELL_EVENTS, own[gi], self._ids
                )
                robot = hit & (rid != -1) & (rid != own[gi])
                if robot.any():
                    out = offset + todo[gi[robot]]
                    t_hit[out] = tt[robot]
                    cell[out] = c._unpad(flat[robot])
                    hit_robot[out] = rid[robot]
                s[_T, wi] = t_cov
                done = wi[hit | (t_cov >= s[_LIM, wi])]
                alive[done] = False
                s[_LIM, done] = -1.0
            n_alive = np.count_nonzero(alive)
            if n_alive < COMPACT_BELOW * s.shape[1]:
                s = s.take(np.flatnonzero(alive), axis=1)


def polygon_cells(
    vertices_xy: np.ndarray,
    resolution: float,
    origin_xy: tuple[float, float],
    shape: tuple[int, int],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rasterise polygons (one per robot) to grid cells: ``(rows, cols, polygon index)``.

    ``vertices_xy`` is (M, 2) for one polygon or (P, M, 2) for P polygons with M vertices each
    (repeat a vertex to pad shorter ones); convex or concave, either orientation. A cell belongs to
    a polygon if its centre lies inside (even-odd rule) **or** an edge of the polygon passes through
    the cell's interior (an edge lying exactly on a grid line counts for the cell above / right of
    it), so bodies thinner than a cell are never lost. Cells outside ``shape`` (rows, cols) are
    dropped; each (polygon, cell) pair appears once, sorted by polygon, row, column.
    """
    v = np.asarray(vertices_xy, dtype=np.float64)
    if v.ndim == 2:
        v = v[None]
    npoly, nv = v.shape[:2]
    x = (v[..., 0] - origin_xy[0]) / resolution
    y = (v[..., 1] - origin_xy[1]) / resolution
    x2, y2 = np.roll(x, -1, axis=1), np.roll(y, -1, axis=1)
    # Work in each polygon's bounding box of cells, padded to the largest box of the batch.
    c0, r0 = np.floor(x.min(axis=1)), np.floor(y.min(axis=1))
    bw = int(np.max(np.floor(x.max(axis=1)) - c0)) + 1
    bh = int(np.max(np.floor(y.max(axis=1)) - r0)) + 1
    box = np.arange(npoly)[:, None] * (bh * (bw + 1))
    # Centres inside, by scanlines: where an edge crosses a row's centre line, toggle every cell
    # from the first centre right of the crossing on; the parity of toggles is the even-odd rule.
    cy = (r0[:, None] + 0.5) + np.arange(bh)  # (P, bh)
    toggles = []
    with np.errstate(divide="ignore", invalid="ignore"):
        for e in range(nv):
            xa, ya, xb, yb = (a[:, e, None] for a in (x, y, x2, y2))
            crosses = (ya > cy) != (yb > cy)
            xc = xa + (cy - ya) * (xb - xa) / (yb - ya)
            first = np.clip(np.ceil(xc - 0.5) - c0[:, None], 0, bw)
            row_base = box + np.arange(bh) * (bw + 1)
            toggles.append((row_base + first)[crosses])
        flips = np.bincount(np.concatenate(toggles).astype(np.intp), minlength=npoly * bh * (bw + 1))
        mask = (np.cumsum(flips.reshape(npoly, bh, bw + 1), axis=2) & 1)[:, :, :bw].astype(bool)
        # Edge cells: between consecutive grid-line crossings an edge stays inside one cell, so the
        # midpoints of those pieces name every cell the edge passes through.
        dx, dy = x2 - x, y2 - y
        nx = int(np.max(np.abs(np.floor(x2) - np.floor(x)))) + 1
        ny = int(np.max(np.abs(np.floor(y2) - np.floor(y)))) + 1
        sx = (np.floor(np.minimum(x, x2))[..., None] + 1 + np.arange(nx) - x[..., None]) / dx[..., None]
        sy = (np.floor(np.minimum(y, y2))[..., None] + 1 + np.arange(ny) - y[..., None]) / dy[..., None]
    ends = np.zeros((npoly, nv, 1))
    cuts = np.concatenate([ends, sx, sy, ends + 1.0], axis=2)
    cuts[~((cuts >= 0) & (cuts <= 1))] = 1.0
    cuts.sort(axis=2)
    mid = 0.5 * (cuts[..., :-1] + cuts[..., 1:])
    ex = np.floor(x[..., None] + mid * dx[..., None]) - c0[:, None, None]
    ey = np.floor(y[..., None] + mid * dy[..., None]) - r0[:, None, None]
    poly = np.broadcast_to(np.arange(npoly)[:, None, None], ex.shape)
    ey = np.clip(ey, 0, bh - 1).astype(np.intp)
    ex = np.clip(ex, 0, bw - 1).astype(np.intp)
    mask[poly.ravel(), ey.ravel(), ex.ravel()] = True
    pp, ri, ci = np.nonzero(mask)
    rows = (r0[pp] + ri).astype(np.int64)
    cols = (c0[pp] + ci).astype(np.int64)
    ok = (rows >= 0) & (rows < shape[0]) & (cols >= 0) & (cols < shape[1])
    return rows[ok], cols[ok], pp[ok]
