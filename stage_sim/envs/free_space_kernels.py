"""Compiled (numba) twins of free space's steps at an obstacles reset: the regions of the valid centres
(``scipy.ndimage.label`` with 8-connectivity) and, in one pass, the filled footprints of an episode's new bodies
(:func:`~stage_sim.maps.polygon_raster.fill_cells`, the same arithmetic) with the centres they put too near
(what :meth:`~stage_sim.envs.free_space.FreeSpace.with_world` finds with distance transforms around them).

Why: an obstacles episode redoes both once per reset, and scipy takes milliseconds on a 30 m world at 5 cm.
Labels: one raster pass with a union-find whose roots are always the older provisional label, then labels numbered
by their region's first cell in raster order, as scipy numbers them. Near cells: every cell within the reach of a
blocked cell's disk of offsets, the disk drawn with the very distances scipy's exact transform computes
(``sqrt(dy² + dx²) · resolution``, compared the same way), a run of blocked cells at a time. Both give the
reference's arrays bit for bit (``tests/envs/test_free_space_kernels.py``, ``tests/envs/test_placement.py``). Used
when the simulation runs the numba kernels. Footprints: a cell is inside when its centre is left of an odd number
of the polygons' edges that span its row (even-odd), each crossing computed as numpy computes it; numpy's version
costs some 0.1 ms of small array operations per box.
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


def clear_near(valid: np.ndarray, blocked: np.ndarray, spans: np.ndarray) -> None:
    """Clear in ``valid`` (H, W) every cell ``blocked`` (H, W) holds and every cell of a disk around one of them,
    given by its rows: ``spans`` (R, 3) holds (row offset, first and last column offset) of each (a disk's row is
    one run of cells). A whole world's free space; :func:`add_bodies` clears near an episode's new bodies the
    same way (:func:`_clear_near_box`), in their boxes only."""
    height, width = valid.shape
    _clear_near_box(valid, blocked, np.array([0, height, 0, width], dtype=np.int64), spans,
                    np.empty(0, dtype=np.int64), -1)


def add_bodies(blocked: np.ndarray, valid: np.ndarray, bodies: list[StaticBody],
               spans: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mark in ``blocked`` (their grid, (H, W)) the filled footprints of ``bodies``, what
    :attr:`~stage_sim.maps.raster.StaticBody.cells` holds (their outline and the cells whose centre is inside),
    and clear in ``valid`` (H, W), which holds no cell within ``spans`` (see :func:`clear_near`) of a cell
    ``blocked`` holds, every cell within them of a cell the bodies block: the free space of a world with bodies
    added, in one pass. Returns the flat cells ``valid`` lost (sorted) and
    each body's box on the grid, (B, 4): first row, last row + 1, first column, last column + 1."""
    resolution, origin, _ = bodies[0].frame
    polygons = [np.asarray(polygon, dtype=np.float64) for body in bodies for polygon in body.polygons]
    points = np.ascontiguousarray(np.concatenate(polygons))
    polygon_starts = np.cumsum([0, *(len(polygon) for polygon in polygons)]).astype(np.int64)
    body_polygons = np.cumsum([0, *(len(body.polygons) for body in bodies)]).astype(np.int64)
    outlines = np.concatenate([body.outline for body in bodies]).astype(np.int64, copy=False)
    outline_starts = np.cumsum([0, *(body.outline.size for body in bodies)]).astype(np.int64)
    boxes = np.empty((len(bodies), 4), dtype=np.int64)
    lost = add_bodies_into(blocked, valid, outlines, outline_starts, points, polygon_starts, body_polygons,
                           float(resolution), float(origin[0]), float(origin[1]), spans, boxes)
    return lost, boxes


@numba.njit(**_JIT)
def add_bodies_into(blocked, valid, outlines, outline_starts, points, polygon_starts, body_polygons, resolution,
                    origin_x, origin_y, spans, boxes):
    """:func:`add_bodies`. A cell is inside a body when its centre is left of an odd number of its polygons' edges
    that span its row (even-odd over all of them), looked at in the polygons' bounding box cut to the grid. Then
    the cells near each body's box are cleared (:func:`_clear_near_box`) and the lost ones sorted."""
    height, width = blocked.shape
    for b in range(outline_starts.size - 1):
        row0, row1, col0, col1 = height, 0, width, 0
        for k in range(outline_starts[b], outline_starts[b + 1]):
            r, c = outlines[k] // width, outlines[k] % width
            row0, row1, col0, col1 = min(row0, r), max(row1, r + 1), min(col0, c), max(col1, c + 1)
            blocked[r, c] = True
        first, last = polygon_starts[body_polygons[b]], polygon_starts[body_polygons[b + 1]]
        x_low, y_low = points[first:last, 0].min(), points[first:last, 1].min()
        x_high, y_high = points[first:last, 0].max(), points[first:last, 1].max()
        fill_col0 = max(math.floor((x_low - origin_x) / resolution), 0)
        fill_row0 = max(math.floor((y_low - origin_y) / resolution), 0)
        fill_col1 = min(math.ceil((x_high - origin_x) / resolution), width)
        fill_row1 = min(math.ceil((y_high - origin_y) / resolution), height)
        for r in range(fill_row0, fill_row1):
            cy = origin_y + (r + 0.5) * resolution
            for c in range(fill_col0, fill_col1):
                cx = origin_x + (c + 0.5) * resolution
                inside = False
                for p in range(body_polygons[b], body_polygons[b + 1]):
                    a, m = polygon_starts[p], polygon_starts[p + 1] - polygon_starts[p]
                    for i in range(m):
                        x1, y1 = points[a + i, 0], points[a + i, 1]
                        j = a + (i + 1) % m
                        x2, y2 = points[j, 0], points[j, 1]
                        if y1 != y2 and min(y1, y2) < cy <= max(y1, y2) and cx < x1 + (cy - y1) * (x2 - x1) / (y2 - y1):
                            inside = not inside
                if inside:
                    row0, row1, col0, col1 = min(row0, r), max(row1, r + 1), min(col0, c), max(col1, c + 1)
                    blocked[r, c] = True
        boxes[b, 0], boxes[b, 1], boxes[b, 2], boxes[b, 3] = row0, row1, col0, col1
    lost = np.empty(valid.size, dtype=np.int64)
    gone = 0
    for b in range(boxes.shape[0]):
        gone = _clear_near_box(valid, blocked, boxes[b], spans, lost, gone)
    return _row_major(lost[:gone], height, width)


@numba.njit(**_JIT)
def _clear_near_box(valid, blocked, box, spans, lost, gone):
    """Clear in ``valid`` the cells within ``spans`` of a blocked cell in ``box`` (first row, last row + 1, first
    column, last column + 1), appending those that were set to ``lost`` from ``gone`` on (``gone`` -1: keep no
    list); returns the new count. Row by row: a run of blocked cells clears, in each row of the disk, one run
    from its first cell's disk to its last's (their disks' union), and the runs a row gets are summed in a
    difference array before it is cleared, so that no cell is looked at once per disk. In an episode's box,
    blocked cells that are not new clear only cells already invalid (none is valid within reach of one)."""
    height, width = valid.shape
    rise, widest = np.abs(spans[:, 0]).max(), max(-spans[:, 1].min(), spans[:, 2].max())
    top, bottom = max(box[0] - rise, 0), min(box[1] + rise, height)
    left, right = max(box[2] - widest, 0), min(box[3] + widest, width)
    if top >= bottom or left >= right:
        return gone
    runs = np.zeros((bottom - top, right - left + 1), dtype=np.int32)
    for r in range(box[0], box[1]):
        c = box[2]
        while c < box[3]:
            if not blocked[r, c]:
                c += 1
                continue
            first = c
            while c < box[3] and blocked[r, c]:
                c += 1
            for k in range(spans.shape[0]):
                rr = r + spans[k, 0]
                low, high = max(first + spans[k, 1], 0), min(c - 1 + spans[k, 2], width - 1)
                if 0 <= rr < height and low <= high:
                    runs[rr - top, low - left] += 1
                    runs[rr - top, high + 1 - left] -= 1
    for rr in range(top, bottom):
        covered = 0
        for cc in range(left, right):
            covered += runs[rr - top, cc - left]
            if covered > 0 and valid[rr, cc]:
                valid[rr, cc] = False
                if gone >= 0:
                    lost[gone] = rr * width + cc
                    gone += 1
    return gone


@numba.njit(**_JIT)
def _row_major(cells, height, width):
    """``cells`` (distinct flat cells of an (H, W) grid) sorted: counted into their rows, then each row's few
    sorted by insertion (a general sort of some thousand cells costs ten times more)."""
    starts = np.zeros(height + 1, dtype=np.int64)
    for cell in cells:
        starts[cell // width + 1] += 1
    for r in range(height):
        starts[r + 1] += starts[r]
    out = np.empty_like(cells)
    filled = starts[:-1].copy()
    for cell in cells:
        r = cell // width
        out[filled[r]] = cell
        filled[r] += 1
    for r in range(height):
        for i in range(starts[r] + 1, starts[r + 1]):
            value, j = out[i], i - 1
            while j >= starts[r] and out[j] > value:
                out[j + 1] = out[j]
                j -= 1
            out[j + 1] = value
    return out


@numba.njit(**_JIT)
def first_fit(cells, shift, positions, width, xs, ys, avoid, separation, away_from, min_distance, out):
    """The first of the candidate valid centres at ``positions`` among the pool of sorted flat ``cells`` less
    those removed (``shift``: :class:`~stage_sim.envs.free_space._CellIndex`'s; empty: none removed) that keeps
    ``separation`` from every row of ``avoid`` (M, 2) and ``min_distance`` from ``away_from`` (empty: no such
    point): its centre into ``out`` (2,) and its index among the candidates, or -1. What a draw's batch of
    candidates finds with numpy (:meth:`~stage_sim.envs.free_space.FreeSpace.draw`), the same arithmetic: the
    candidates' cells looked up as ``take`` looks them up, their centres from the column and row centres ``xs``
    and ``ys``, ``sqrt`` of the least ``dx² + dy²``. Why: some fifteen numpy calls on 64 candidates cost a draw
    about 40 µs, and a reset of the obstacles scenario draws ten."""
    for k in range(positions.size):
        position = positions[k]
        cell = cells[position + np.searchsorted(shift, position, side="right")]
        x, y = xs[cell % width], ys[cell // width]
        ok = True
        if avoid.shape[0]:
            nearest = np.inf
            for j in range(avoid.shape[0]):
                dx, dy = x - avoid[j, 0], y - avoid[j, 1]
                nearest = min(nearest, dx * dx + dy * dy)
            ok = math.sqrt(nearest) >= separation
        if ok and away_from.size:
            dx, dy = x - away_from[0], y - away_from[1]
            ok = math.sqrt(dx * dx + dy * dy) >= min_distance
        if ok:
            out[0], out[1] = x, y
            return k
    return -1
