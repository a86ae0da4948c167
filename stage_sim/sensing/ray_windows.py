"""Exact resolution of rays over a few grid-line crossings: the kernels behind :mod:`~stage_sim.sensing.raycast`.

The caster's free-space jumps only decide where exact work is needed; this module does that work with
the traversal's own formulas (see the maths in :mod:`stage_sim.sensing.raycast`), many rays at a time:

* :meth:`RayWindows.segments` – the next few *segments* of each ray (straight runs of cells between
  two minor-axis grid-line crossings), one free-run lookup per segment: cheap along walls.
* :meth:`RayWindows.cells` – the next few crossings of each axis, every entered cell looked up: slower,
  but it also sees robot cells and handles rays that start outside the grid.

Arrays are laid out (event, ray), so the per-ray constants of :meth:`RayWindows.constants` broadcast.
"""

from __future__ import annotations

import numpy as np

from stage_sim.sensing.distance_field import run_lengths

#: Free border (cells) around every stored field, so positions on the grid's edge index safely.
PAD = 1
#: Positional safety margin in cells: far above float64 rounding of cell coordinates (~1e-12 for
#: grids up to 1e4 cells), far below a cell, so a certified jump never reaches an unchecked cell.
EPS = 1e-6
#: Upper bound of segments per window (bounds the memory of tiny, long-range batches).
MAX_SEGMENTS = 256
#: Cached ramp length for :meth:`RayWindows.arange`.
_INDEX_SIZE = 1 << 16

# Rows of the per-ray constant matrix used by the exact windows (major axis a, minor axis b).
(_PA, _PB, _DA, _DB, _IA, _IB, _SA, _SB, _A0, _B0, _CAO, _PAB, _PBB, _STA, _STB, _BASE, _CBN, _YMAJ, _REFF) = range(19)
_NG = 19


class RayWindows:
    """Exact window kernels on one padded static layer (``PAD`` free cells around the grid)."""

    def __init__(self, occupied: np.ndarray) -> None:
        occ = np.asarray(occupied, dtype=bool)
        self.height, self.width = occ.shape
        padded = np.zeros((self.height + 2 * PAD, self.width + 2 * PAD), dtype=bool)
        padded[PAD:-PAD, PAD:-PAD] = occ
        self.padded = padded
        self.hp, self.wp = padded.shape
        self._occ_flat = padded.ravel()
        self._runs = run_lengths(padded).ravel()
        self._index = np.arange(_INDEX_SIZE)
        self._ramps = {j: np.arange(j, dtype=np.float64)[:, None] for j in range(MAX_SEGMENTS + 2)}

    def arange(self, n: int) -> np.ndarray:
        """0, 1, ..., n − 1 (cached for the usual sizes)."""
        return self._index[:n] if n <= self._index.size else np.arange(n)

    def unpad(self, flat: np.ndarray) -> np.ndarray:
        """Padded flat index -> flat index ``row * width + col`` of the unpadded grid."""
        row, col = np.divmod(flat, self.wp)
        return ((row - PAD) * self.width + (col - PAD)).astype(np.int64)

    def constants(self, uv, d, inv, lim) -> np.ndarray:
        """Per-ray constants of the exact segment windows, in (major a, minor b) axis terms."""
        hw = float(self.hp * self.wp)
        wp = float(self.wp)
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

    def segments(self, g, gid, ids, ts, segments: int, t_hit, cell) -> tuple[np.ndarray, np.ndarray]:
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
        fi += self.arange(m)
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

    def cells(self, g, ts, lim, events: int, owner=None, robot_ids=None, clip=False):
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
        hp, wp = float(self.hp), float(self.wp)
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
            pick = np.minimum(first, events - 1) * tj.shape[1] + self.arange(tj.shape[1])
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
