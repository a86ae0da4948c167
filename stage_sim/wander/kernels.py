"""The wanderer's compiled inner loops (numba): the arc clearance check, the turning-circle check and the
marking of the cells a scan crossed.

Each does, element by element, the same float operations in the same order as the vectorised formulas it
replaced (numba without fastmath neither fuses multiply-adds nor reassociates; ``math.hypot`` is the C
library's, as ``np.hypot``'s is), so the wanderer decides exactly as before (``tests/wander/
test_decisions.py`` replays recorded runs); they only spare the large temporary arrays, and the arc check
stops at an arc's first collision, after which nothing about the arc matters. Without numba the same
functions run as plain Python (``tests/wander/test_kernel_fallback.py``). Compiled on first use and
cached on disk (``cache=True``: where :mod:`stage_sim.backend` sends numba's cache);
:func:`warm_up` loads them before a robot's first scan, so that no decision waits for the compiler.
"""

from __future__ import annotations

import math

import numpy as np

from stage_sim.backend import numba_available


def _compiled(function):
    """``numba.njit(cache=True)`` of ``function``, or the function itself when numba is unavailable
    (:func:`~stage_sim.backend.numba_available` warns once; the same loops then run as plain Python: same
    decisions, slower)."""
    if not numba_available():
        return function
    import numba

    return numba.njit(cache=True)(function)


ROUNDING = 1e-9  # m: far more than the rounding error of any distance the checks compare


@_compiled
def _body_distance(x: float, y: float, boxes: np.ndarray) -> float:
    """Distance from a body-frame point to the nearest of the body's rectangles (0 inside)."""
    best = math.inf
    for b in range(boxes.shape[0]):
        dx = max(max(x - boxes[b, 1], boxes[b, 0] - x), 0.0)
        dy = max(max(y - boxes[b, 3], boxes[b, 2] - y), 0.0)
        best = min(best, math.hypot(dx, dy))
    return best


@_compiled
def arc_margins(
    x: np.ndarray, y: np.ndarray, cos: np.ndarray, sin: np.ndarray, counts: np.ndarray, px: np.ndarray,
    py: np.ndarray, near: np.ndarray, limit: np.ndarray, boxes: np.ndarray, radius: float,
) -> np.ndarray:
    """Per candidate and check time (C, T): the least margin ``body distance - limit[t, p]`` of the body at the
    arc pose (``x``, ``y`` and the cosine and sine of its yaw, each (C, T)) over the first ``counts[c]``
    points (``px``, ``py``, no farther than ``near`` from the origin and sorted by it); inf with no points.
    The body lies within ``radius`` of its origin.

    Only the sign of a margin after an arc's first hit matters (and not even that once the arc is hit), so
    an arc's check stops at its first negative margin after the first time (the later times read -inf); at
    the first time the least margin is exact (it ranks the arcs when none stays clear). A point whose
    distance from the body's origin, less ``radius``, leaves a margin above the least so far (by more than
    any rounding) cannot lower it and is skipped; once even the nearest a point may be leaves that margin
    for the largest limit, so does every point after it, and the check moves on."""
    candidates, times = x.shape
    closest = np.full((candidates, times), np.inf)
    most = np.empty_like(limit)  # the largest limit among the first p + 1 points
    for t in range(times):
        for p in range(limit.shape[1]):
            most[t, p] = limit[t, p] if p == 0 else max(most[t, p - 1], limit[t, p])
    for c in range(candidates):
        for t in range(times):
            least = math.inf
            cx, cy, co, si = x[c, t], y[c, t], cos[c, t], sin[c, t]
            origin = math.hypot(cx, cy)
            for p in range(counts[c]):
                if near[p] - origin - radius - most[t, counts[c] - 1] > least + ROUNDING:
                    break
                dx, dy = px[p] - cx, py[p] - cy
                if math.sqrt(dx * dx + dy * dy) - radius - limit[t, p] > least + ROUNDING:
                    continue
                least = min(least, _body_distance(co * dx + si * dy, co * dy - si * dx, boxes) - limit[t, p])
                if least < 0 and t > 0:
                    break
            closest[c, t] = least
            if least < 0:
                closest[c, t + 1:] = -np.inf
                break
    return closest


@_compiled
def nearest_distance(x: np.ndarray, y: np.ndarray, px: np.ndarray, py: np.ndarray, near: np.ndarray) -> np.ndarray:
    """Per pose (``x[c]``, ``y[c]``) the distance to the nearest point (``px``, ``py``, no farther than ``near``
    from the origin and sorted by it); inf with none."""
    nearest = np.full(x.shape[0], np.inf)
    for c in range(x.shape[0]):
        origin = math.hypot(x[c], y[c])
        for p in range(px.shape[0]):
            if near[p] - origin > nearest[c] + ROUNDING:
                break
            nearest[c] = min(nearest[c], math.hypot(px[p] - x[c], py[p] - y[c]))
    return nearest


@_compiled
def _collect(x: float, y: float, cell: float, half: int, side: int, flags: np.ndarray, found: np.ndarray,
             n: int, bounds: np.ndarray) -> int:
    """Append the flat index of the grid cell holding (x, y) to ``found[:n]`` unless it is off the grid or
    already there (``flags``); widen ``bounds`` (i_min, j_min, i_max, j_max) by it. Returns the new count."""
    i = np.int64(math.floor(x / cell)) + half
    j = np.int64(math.floor(y / cell)) + half
    if i < 0 or i >= side or j < 0 or j >= side:
        return n
    flat = i * side + j
    if flags[flat]:
        return n
    flags[flat] = 1
    found[n] = flat
    bounds[0], bounds[1] = min(bounds[0], i), min(bounds[1], j)
    bounds[2], bounds[3] = max(bounds[2], i), max(bounds[3], j)
    return n + 1


@_compiled
def _add_once(cells: np.ndarray, flags: np.ndarray, found: np.ndarray, n: int, amount: int, clip: int) -> None:
    """Add ``amount`` (clipped to ±``clip``) once to each cell of ``found[:n]``, and clear their flags."""
    for k in range(n):
        flat = found[k]
        cells[flat] = min(max(np.int64(cells[flat]) + amount, -clip), clip)
        flags[flat] = 0


@_compiled
def mark_scan(
    cells: np.ndarray, flags: np.ndarray, origin: np.ndarray, ends: np.ndarray, hit: np.ndarray,
    lengths: np.ndarray, steps: np.ndarray, extra: np.ndarray, cell: float, half: int, side: int,
    passed: int, ended: int, clip: int,
) -> np.ndarray:
    """One scan into a flat grid of scores ``cells`` (side × side, cell ``cell`` m, index 0 at -half cells):
    ``passed`` is added once to each cell crossed by a beam from ``origin`` to ``ends`` (sampled at ``steps``
    along it, up to a cell short of a hit), to the cells of the misses' ends and of the ``extra`` points; then
    ``ended`` once to each cell a hit ended in. ``flags`` (all zero, one per cell) is scratch. Returns the
    bounds (i_min, j_min, i_max, j_max) of the cells touched (min > max when none was)."""
    beams = ends.shape[0]
    found = np.empty(beams * steps.shape[0] + beams + extra.shape[0], dtype=np.int64)
    bounds = np.array([side, side, -1, -1], dtype=np.int64)
    n = 0
    for b in range(beams):
        reach = lengths[b] - (cell if hit[b] else 0.0)
        length = max(lengths[b], 1e-9)
        ex, ey = ends[b, 0] - origin[0], ends[b, 1] - origin[1]
        for k in range(steps.shape[0]):
            if not steps[k] <= reach:
                break
            fraction = steps[k] / length
            n = _collect(origin[0] + fraction * ex, origin[1] + fraction * ey, cell, half, side, flags, found, n,
                         bounds)
    for b in range(beams):
        if not hit[b]:
            n = _collect(ends[b, 0], ends[b, 1], cell, half, side, flags, found, n, bounds)
    for e in range(extra.shape[0]):
        n = _collect(extra[e, 0], extra[e, 1], cell, half, side, flags, found, n, bounds)
    _add_once(cells, flags, found, n, passed, clip)
    n = 0
    for b in range(beams):
        if hit[b]:
            n = _collect(ends[b, 0], ends[b, 1], cell, half, side, flags, found, n, bounds)
    _add_once(cells, flags, found, n, ended, clip)
    return bounds


def warm_up() -> None:
    """Compile (or load from the cache) every kernel now, on tiny inputs."""
    table = np.zeros((1, 1))
    arc_margins(table, table, table, table, np.zeros(1, dtype=np.int64), np.zeros(0), np.zeros(0), np.zeros(0),
                table, np.zeros((1, 4)), 1.0)
    nearest_distance(np.zeros(1), np.zeros(1), np.zeros(0), np.zeros(0), np.zeros(0))
    mark_scan(np.zeros(4, dtype=np.int8), np.zeros(4, dtype=np.uint8), np.zeros(2), np.zeros((1, 2)),
              np.zeros(1, dtype=np.bool_), np.zeros(1), np.zeros(1), np.zeros((0, 2)), 1.0, 1, 2, -1, 3, 6)
