"""Turning polygons into grid cells: filled static bodies and sampled outlines of moving bodies.

Cell (row r, col c) covers x ∈ [x0 + c·res, x0 + (c+1)·res), y ∈ [y0 + r·res, y0 + (r+1)·res), with
(x0, y0) the grid origin (lower-left corner of cell (0, 0)); flat index = r·width + c.

Static bodies are *filled*: a cell belongs to a polygon when its centre is inside (even-odd rule) or when
an edge of the polygon passes through it, so walls thinner than a cell are never lost. Robots are
represented by points sampled densely along their outlines (at most half a cell apart), which is what
Stage rasterises too: a ray or another body cannot reach the inside without crossing the outline, and the
outline is cheap to move every step for thousands of robots.
"""

from __future__ import annotations

import numpy as np

# Edge sampling step as a fraction of the cell size: a quarter cell keeps every cell an edge crosses by
# more than a sliver, at a cost that only matters once, when the static world is built.
EDGE_SAMPLES_PER_CELL = 4


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
    """Sorted unique flat indices of the cells a filled polygon (M, 2) in world coordinates covers."""
    edge_cells = point_cells(outline_points(polygon, resolution / EDGE_SAMPLES_PER_CELL), resolution, origin_xy, shape)
    low = np.floor((polygon.min(axis=0) - origin_xy) / resolution).astype(int)
    high = np.ceil((polygon.max(axis=0) - origin_xy) / resolution).astype(int)
    col0, row0 = np.maximum(low, 0)
    col1, row1 = np.minimum(high, (shape[1], shape[0]))
    inner = np.empty(0, dtype=np.int64)
    if col1 > col0 and row1 > row0:
        cols = np.arange(col0, col1)
        rows = np.arange(row0, row1)
        cx = origin_xy[0] + (cols + 0.5) * resolution
        cy = origin_xy[1] + (rows + 0.5) * resolution
        inside = _centres_inside(polygon, cx, cy)
        r, c = np.nonzero(inside)
        inner = (rows[r] * shape[1] + cols[c]).astype(np.int64)
    cells = np.concatenate([inner, edge_cells[edge_cells >= 0]])
    return np.unique(cells)


def _centres_inside(polygon: np.ndarray, cx: np.ndarray, cy: np.ndarray) -> np.ndarray:
    """Even-odd test of the grid of centres (len(cy), len(cx)) against the polygon, one edge at a time."""
    inside = np.zeros((len(cy), len(cx)), dtype=bool)
    x1s, y1s = polygon[:, 0], polygon[:, 1]
    x2s, y2s = np.roll(x1s, -1), np.roll(y1s, -1)
    for x1, y1, x2, y2 in zip(x1s, y1s, x2s, y2s, strict=True):
        if y1 == y2:
            continue
        spans = (cy > min(y1, y2)) & (cy <= max(y1, y2))
        if not spans.any():
            continue
        x_cross = x1 + (cy[spans] - y1) * (x2 - x1) / (y2 - y1)
        inside[spans] ^= cx[None, :] < x_cross[:, None]
    return inside
