"""Compiled (numba) twins of free space's steps at an obstacles reset: the regions of the valid centres
(``scipy.ndimage.label`` with 8-connectivity), the centres too near an episode's new bodies (what
:meth:`~stage_sim.envs.free_space.FreeSpace.with_world` finds with distance transforms around them) and the
filled footprints of those bodies (:func:`~stage_sim.maps.polygon_raster.fill_cells`, the same arithmetic).

Why: an obstacles episode redoes both once per reset, and scipy takes milliseconds on a 30 m world at 5 cm.
Labels: one raster pass with a union-find whose roots are always the older provisional label, then labels
numbered by their region's first cell in raster order, as scipy numbers them. Near cells: every cell within
the reach of a new cell's disk of offsets, the disk drawn with the very distances scipy's exact transform
computes (``sqrt(dy² + dx²) · resolution``, compared the same way). Both give the reference's arrays bit for
bit (``tests/envs/test_free_space_kernels.py``, ``tests/envs/test_placement.py``). Used when the simulation
runs the numba kernels. Footprints: a cell is inside when its centre is left of an odd number of the polygons'
edges that span its row (even-odd), each crossing computed as numpy computes it; numpy's version costs some
0.1 ms of small array operations per box.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from stage_sim.maps.raster import StaticBody

_JIT = {"cache": True, "nogil": True}


def label8(valid: np.ndarray) -> tuple[np.ndarray, int]:
    """``scipy.ndimage.label(valid, structure=np.ones((3, 3)))``: int32 labels (H, W) and their count."""
    labels = np.zeros(valid.shape, dtype=np.int32)
    count = label_into(np.ascontiguousarray(valid, dtype=np.bool_), labels)
    return labels, int(count)


@numba.njit(inline="always", **_JIT)
def _root(parent, label):
    """The root of ``label``, halving the path on the way."""
    while parent[label] != label:
        parent[label] = parent[parent[label]]
        label = parent[label]
    return label


@numba.njit(inline="always", **_JIT)
def _join(parent, a, b):
    """Merge the sets of roots-to-be ``a`` and ``b`` under the smaller root; returns it."""
    a, b = _root(parent, a), _root(parent, b)
    if a < b:
        parent[b] = a
        return a
    parent[a] = b
    return b


@numba.njit(**_JIT)
def label_into(valid, labels):
    """Write the 8-connected regions of ``valid`` (H, W) into the zeroed ``labels``, numbered 1.. in the raster
    order of each region's first cell; returns how many there are."""
    height, width = valid.shape
    parent = np.empty(height * width + 1, dtype=np.int32)
    made = 0
    for r in range(height):
        for c in range(width):
            if not valid[r, c]:
                continue
            # A labelled north neighbour is already joined with the other three (all are 8-neighbours of it);
            # west and north-west are joined with each other; only north-east may need joining.
            north = labels[r - 1, c] if r > 0 else 0
            if north:
                found = north
            else:
                east = labels[r - 1, c + 1] if r > 0 and c + 1 < width else 0
                west = labels[r, c - 1] if c > 0 else 0
                if west == 0 and r > 0 and c > 0:
                    west = labels[r - 1, c - 1]
                if east and west:
                    found = _join(parent, east, west)
                elif east or west:
                    found = east or west
                else:
                    made += 1
                    parent[made] = made
                    found = made
            labels[r, c] = found
    final = np.zeros(made + 1, dtype=np.int32)
    count = 0
    for label in range(1, made + 1):
        root = _root(parent, label)
        if root == label:
            count += 1
            final[label] = count
        else:
            final[label] = final[root]  # a root is older than every label it holds: numbered already
    for r in range(height):
        for c in range(width):
            labels[r, c] = final[labels[r, c]]
    return count


def clear_near(valid: np.ndarray, added: np.ndarray, cells: np.ndarray, spans: np.ndarray) -> None:
    """Clear in ``valid`` (H, W) the flat ``cells`` of ``added`` (H, W) and every cell of a disk around one of
    them, given by its rows: ``spans`` (R, 3) holds (row offset, first and last column offset) of each (a disk's
    row is one run of cells, cleared in one inner loop). Only the cells with a neighbour not added draw their
    disk: the cell of ``added`` nearest to any other cell is one of those (a step from an inner cell towards it
    comes nearer)."""
    clear_near_into(valid, added, cells, spans)


@numba.njit(**_JIT)
def clear_near_into(valid, added, cells, spans):
    """:func:`clear_near`."""
    height, width = valid.shape
    for cell in cells:
        r, c = cell // width, cell % width
        valid[r, c] = False
        inner = 0 < r < height - 1 and 0 < c < width - 1
        if inner:
            for dr in (-1, 0, 1):
                for dc in (-1, 0, 1):
                    inner = inner and added[r + dr, c + dc]
        if inner:
            continue
        for k in range(spans.shape[0]):
            rr = r + spans[k, 0]
            if 0 <= rr < height:
                for cc in range(max(c + spans[k, 1], 0), min(c + spans[k, 2], width - 1) + 1):
                    valid[rr, cc] = False


def mark_filled(blocked: np.ndarray, body: StaticBody) -> None:
    """Set in ``blocked`` (the body's grid, (H, W)) the cells of ``body``'s filled footprint, what
    :attr:`~stage_sim.maps.raster.StaticBody.cells` holds: its outline and the cells whose centre is inside."""
    blocked.ravel()[body.outline] = True
    resolution, origin, _ = body.frame
    points = np.ascontiguousarray(np.concatenate(body.polygons), dtype=np.float64)
    starts = np.cumsum([0, *(len(polygon) for polygon in body.polygons)]).astype(np.int64)
    mark_inside(blocked, points, starts, float(resolution), float(origin[0]), float(origin[1]))


@numba.njit(**_JIT)
def mark_inside(blocked, points, starts, resolution, origin_x, origin_y):
    """Set in ``blocked`` (H, W) the cells whose centre is inside the polygons ``points[starts[p]:starts[p + 1]]``
    (even-odd over all of them), in their bounding box cut to the grid: :func:`~stage_sim.maps.polygon_raster.
    fill_cells`."""
    height, width = blocked.shape
    x_low, y_low = points[:, 0].min(), points[:, 1].min()
    x_high, y_high = points[:, 0].max(), points[:, 1].max()
    col0 = max(math.floor((x_low - origin_x) / resolution), 0)
    row0 = max(math.floor((y_low - origin_y) / resolution), 0)
    col1 = min(math.ceil((x_high - origin_x) / resolution), width)
    row1 = min(math.ceil((y_high - origin_y) / resolution), height)
    for r in range(row0, row1):
        cy = origin_y + (r + 0.5) * resolution
        for c in range(col0, col1):
            cx = origin_x + (c + 0.5) * resolution
            inside = False
            for p in range(starts.size - 1):
                a, m = starts[p], starts[p + 1] - starts[p]
                for i in range(m):
                    x1, y1 = points[a + i, 0], points[a + i, 1]
                    j = a + (i + 1) % m
                    x2, y2 = points[j, 0], points[j, 1]
                    if y1 != y2 and min(y1, y2) < cy <= max(y1, y2) and cx < x1 + (cy - y1) * (x2 - x1) / (y2 - y1):
                        inside = not inside
            if inside:
                blocked[r, c] = True
