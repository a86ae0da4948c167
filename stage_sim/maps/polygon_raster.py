"""Turning polygons into grid cells: Stage's edge raster, filled footprints and sampled outlines.

Cell (row r, col c) covers x ∈ [x0 + c·res, x0 + (c+1)·res), y ∈ [y0 + r·res, y0 + (r+1)·res), with
(x0, y0) the grid origin (lower-left corner of cell (0, 0)); flat index = r·width + c.

* **Stage's raster** (:func:`vertex_cells`, :func:`edge_cells`): what rays and collisions see. Stage floors
  each polygon vertex to its cell (``floor(x · ppm)``, ppm = 1 / resolution, cells anchored at the world
  origin) and walks each edge from its start cell to its end cell in 4-connected steps (``World::MapPoly``,
  Cohen's integer line), marking every cell but the end one (the next edge starts there). Only edges
  exist: the inside of a polygon is empty unless an edge runs through it.
* **Filled footprints** (:func:`fill_cells`, :func:`fill_polygon`): cells whose centre is inside (even-odd
  rule) or that an edge passes through; what a map of the world shows, never what a ray sees.
* **One polygon's walk** (:func:`edge_walk`): the same cells as :func:`edge_cells`, one polygon at a time in
  plain loops that numba compiles, for the robot bodies rasterised again at every pose
  (:mod:`stage_sim.sim.body_kernels`).
* **Sampled outlines** (:func:`outline_points`): points at most ``spacing`` apart along an outline, for the
  filled footprints.
"""

from __future__ import annotations

import numpy as np

# Edge sampling step as a fraction of the cell size: a quarter cell keeps every cell an edge crosses by
# more than a sliver, at a cost that only matters once, when the static world is built.
EDGE_SAMPLES_PER_CELL = 4


def vertex_cells(points: np.ndarray, resolution: float) -> np.ndarray:
    """Stage's integer cell (col, row) of each world point (M, 2), counted from the world origin."""
    ppm = 1.0 / resolution
    return np.floor(points * ppm).astype(np.int64)


def edge_cells(polygons: list[np.ndarray]) -> np.ndarray:
    """Cells (K, 2) as (col, row) that Stage marks for closed polygons given by vertex cells (M, 2) each.

    Edge a → b with ax = |bx − ax|, ay = |by − ay| takes ax + ay unit steps from a; at each step the error
    term (2i+1)·ay − (2j+1)·ax (after i x-steps and j y-steps) picks x when negative, else y: the cells a
    line from the centre of a's cell to the centre of b's cell passes through, a y-step first on a tie.
    An edge within one cell marks nothing. Cells may repeat.
    """
    if not polygons:
        return np.zeros((0, 2), dtype=np.int64)
    start = np.concatenate(polygons).astype(np.int64)
    end = np.concatenate([np.roll(p, -1, axis=0) for p in polygons]).astype(np.int64)
    return edge_cells_with_edges(start, end)[0]


def edge_cells_with_edges(start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`edge_cells` of the edges ``start[e]`` → ``end[e]`` (E, 2) (vertex cells), with the edge of each
    cell: the cells of edge 0 first, then edge 1's, … (as a robot body's cells are told from its owner)."""
    delta = end - start
    ax, ay = np.abs(delta[:, 0]), np.abs(delta[:, 1])
    steps = ax + ay
    if steps.sum() == 0:
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    edge = np.repeat(np.arange(len(steps)), steps)
    first = np.cumsum(steps) - steps
    k = np.arange(edge.size) - first[edge]
    is_x = k < ax[edge]
    # Step k of an edge is its i-th x-step or j-th y-step; sort each edge's steps by when the centre line
    # crosses the grid line: x-step i at (2i+1)/(2ax), y-step j at (2j+1)/(2ay), y first on a tie.
    nth = np.where(is_x, k, k - ax[edge])
    when = np.where(is_x, 2 * (2 * nth + 1) * ay[edge] + 1, 2 * (2 * nth + 1) * ax[edge])
    is_x = is_x[np.lexsort((when, edge))]
    # Cells are marked before each step: count the x- and y-steps taken earlier on the same edge.
    x_before = np.cumsum(is_x) - is_x
    y_before = np.cumsum(~is_x) - ~is_x
    x_before -= x_before[first[edge]]
    y_before -= y_before[first[edge]]
    direction = np.sign(delta)[edge]
    return start[edge] + direction * np.stack([x_before, y_before], axis=1), edge


def edge_walk(vertices, out, k):
    """Stage's ``World::MapPoly`` for one closed polygon of vertex cells (M, 2) (col, row): write the cells it
    marks into ``out[k:]`` (room for the sum of |Δcol| + |Δrow| over its edges) and return the next free ``k``.

    Cohen's walk as Stage writes it: error ``ay − ax``, an x-step while it is negative (+2·ay), else a y-step
    (−2·ax), each cell marked before its step; the same cells, in the same order, as :func:`edge_cells`.
    Plain loops on purpose: :mod:`stage_sim.sim.body_kernels` compiles this function with numba."""
    m = vertices.shape[0]
    for i in range(m):
        x, y = vertices[i, 0], vertices[i, 1]
        j = i + 1 if i + 1 < m else 0
        dx, dy = vertices[j, 0] - x, vertices[j, 1] - y
        sx = 1 if dx > 0 else (-1 if dx < 0 else 0)
        sy = 1 if dy > 0 else (-1 if dy < 0 else 0)
        ax, ay = abs(dx), abs(dy)
        exy = ay - ax
        for _ in range(ax + ay):
            out[k, 0], out[k, 1] = x, y
            k += 1
            if exy < 0:
                x += sx
                exy += 2 * ay
            else:
                y += sy
                exy -= 2 * ax
    return k


def fill_cells(
    polygons: list[np.ndarray], resolution: float, origin_xy: tuple[float, float], shape: tuple[int, int]
) -> np.ndarray:
    """Sorted unique flat indices of the cells whose centre is inside the polygons (even-odd over all)."""
    if not polygons:
        return np.zeros(0, dtype=np.int64)
    points = np.concatenate(polygons)
    low = np.floor((points.min(axis=0) - origin_xy) / resolution).astype(int)
    high = np.ceil((points.max(axis=0) - origin_xy) / resolution).astype(int)
    col0, row0 = np.maximum(low, 0)
    col1, row1 = np.minimum(high, (shape[1], shape[0]))
    if col1 <= col0 or row1 <= row0:
        return np.zeros(0, dtype=np.int64)
    cols = np.arange(col0, col1)
    rows = np.arange(row0, row1)
    cx = origin_xy[0] + (cols + 0.5) * resolution
    cy = origin_xy[1] + (rows + 0.5) * resolution
    inside = np.zeros((len(cy), len(cx)), dtype=bool)
    for polygon in polygons:
        _toggle_inside(inside, polygon, cx, cy)
    r, c = np.divmod(np.flatnonzero(inside), inside.shape[1])  # np.nonzero of a 2-D grid is several times slower
    return (rows[r] * shape[1] + cols[c]).astype(np.int64)


def outline_points(polygon: np.ndarray, spacing: float) -> np.ndarray:
    """Points (P, 2) along the closed outline of ``polygon`` (M, 2), consecutive ones ≤ ``spacing`` apart."""
    start = polygon
    end = np.roll(polygon, -1, axis=0)
    lengths = np.hypot(*(end - start).T)
    counts = np.maximum(1, np.ceil(lengths / spacing).astype(int))
    fractions = np.concatenate([np.arange(n) / n for n in counts])
    edge_of_sample = np.repeat(np.arange(len(polygon)), counts)
    return start[edge_of_sample] + (end - start)[edge_of_sample] * fractions[:, None]


def point_cells(
    points: np.ndarray, resolution: float, origin_xy: tuple[float, float], shape: tuple[int, int]
) -> np.ndarray:
    """Flat cell index of each point (..., 2); −1 where the point lies outside the grid."""
    cols = np.floor((points[..., 0] - origin_xy[0]) / resolution).astype(np.int64)
    rows = np.floor((points[..., 1] - origin_xy[1]) / resolution).astype(np.int64)
    inside = (cols >= 0) & (cols < shape[1]) & (rows >= 0) & (rows < shape[0])
    return np.where(inside, rows * shape[1] + cols, -1)


def fill_polygon(
    polygon: np.ndarray, resolution: float, origin_xy: tuple[float, float], shape: tuple[int, int]
) -> np.ndarray:
    """Sorted unique flat indices of the cells a filled polygon (M, 2) in world coordinates covers:
    centres inside, plus every cell an edge passes through (sampled), so no thin wall is lost."""
    edge = point_cells(outline_points(polygon, resolution / EDGE_SAMPLES_PER_CELL), resolution, origin_xy, shape)
    return np.unique(np.concatenate([fill_cells([polygon], resolution, origin_xy, shape), edge[edge >= 0]]))


def _toggle_inside(inside: np.ndarray, polygon: np.ndarray, cx: np.ndarray, cy: np.ndarray) -> None:
    """Flip ``inside`` (len(cy), len(cx)) for the centres left of each edge of ``polygon`` (even-odd)."""
    x1s, y1s = polygon[:, 0], polygon[:, 1]
    following = np.arange(1, len(polygon) + 1) % len(polygon)  # np.roll(·, -1), without its overhead
    x2s, y2s = x1s[following], y1s[following]
    for x1, y1, x2, y2 in zip(x1s, y1s, x2s, y2s, strict=True):
        if y1 == y2:
            continue
        spans = (cy > min(y1, y2)) & (cy <= max(y1, y2))
        if not spans.any():
            continue
        x_cross = x1 + (cy[spans] - y1) * (x2 - x1) / (y2 - y1)
        inside[spans] ^= cx[None, :] < x_cross[:, None]
