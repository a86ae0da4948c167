"""Stage's bitmap → polygons conversion (polys_from_image_file): which outlines, which vertices, which order."""

from __future__ import annotations

import numpy as np

from stage_sim.worldfile.bitmap import trace_outlines


def mask(*rows: str) -> np.ndarray:
    """A mask from rows of '#' (occupied) and '.' (free), row 0 at the top."""
    return np.array([[c == "#" for c in row] for row in rows])


def as_lists(polygons: list[np.ndarray]) -> list[list[tuple[float, float]]]:
    return [[(float(x), float(y)) for x, y in p] for p in polygons]


def test_a_rectangle_is_one_polygon_along_its_border_with_y_flipped() -> None:
    # 3 x 2 block at columns 1..3, rows 0..1: corners x in {1, 4}, y in {0, -2}. The walk starts at the
    # smallest corner; the first three vertices are kept as they come, later straight runs are merged, and
    # the last vertex is not merged with the first (Stage's rules), hence (2, 0) and (1, -1).
    polygons = trace_outlines(mask(".###", ".###"))
    assert as_lists(polygons) == [[(1.0, 0.0), (2.0, 0.0), (4.0, 0.0), (4.0, -2.0), (1.0, -2.0), (1.0, -1.0)]]


def test_shared_pixel_edges_cancel_and_a_hole_is_its_own_polygon() -> None:
    ring = mask("###", "#.#", "###")
    polygons = as_lists(trace_outlines(ring))
    assert len(polygons) == 2
    outer, hole = polygons
    assert outer == [(0.0, 0.0), (1.0, 0.0), (3.0, 0.0), (3.0, -3.0), (0.0, -3.0), (0.0, -1.0)]
    # the hole runs the other way round (its edges belong to the pixels around it)
    assert hole == [(1.0, -1.0), (1.0, -2.0), (2.0, -2.0), (2.0, -1.0)]


def test_the_first_three_vertices_are_never_merged() -> None:
    # Stage only merges a new vertex into the previous one once the polygon has three: a 1-pixel-high
    # bar 3 pixels long keeps the corner-to-corner run of its first edge as separate unit steps.
    polygons = as_lists(trace_outlines(mask("###")))
    assert polygons == [[(0.0, 0.0), (1.0, 0.0), (3.0, 0.0), (3.0, -1.0), (0.0, -1.0)]]


def test_at_a_corner_with_two_ways_on_the_smaller_end_corner_is_taken() -> None:
    # Pixels touching at a corner: from the shared corner (1, -1) the walk around the first pixel can go
    # on to (0, -1) or to (2, -1); Stage takes the smaller, which closes the first square.
    polygons = as_lists(trace_outlines(mask("#.", ".#")))
    assert polygons == [
        [(0.0, 0.0), (1.0, 0.0), (1.0, -1.0), (0.0, -1.0)],
        [(1.0, -1.0), (2.0, -1.0), (2.0, -2.0), (1.0, -2.0)],
    ]


def test_every_border_edge_of_a_random_mask_is_on_an_outline_once() -> None:
    rng = np.random.default_rng(3)
    occupied = rng.random((12, 15)) < 0.45
    polygons = trace_outlines(occupied)
    traced = set()
    for polygon in polygons:
        for (x0, y0), (x1, y1) in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
            # split merged runs back into unit pixel edges, as (x, image row) corner pairs
            steps = int(abs(x1 - x0) + abs(y1 - y0))
            for k in range(steps):
                a = (x0 + (x1 - x0) * k / steps, -(y0 + (y1 - y0) * k / steps))
                b = (x0 + (x1 - x0) * (k + 1) / steps, -(y0 + (y1 - y0) * (k + 1) / steps))
                edge = (a, b)
                assert edge not in traced
                traced.add(edge)
    padded = np.pad(occupied, 1)
    expected = set()
    for r, c in zip(*np.nonzero(occupied), strict=True):
        if not padded[r, c + 1]:
            expected.add(((c, r), (c + 1, r)))
        if not padded[r + 1, c + 2]:
            expected.add(((c + 1, r), (c + 1, r + 1)))
        if not padded[r + 2, c + 1]:
            expected.add(((c + 1, r + 1), (c, r + 1)))
        if not padded[r + 1, c]:
            expected.add(((c, r + 1), (c, r)))
    assert traced == {((float(a), float(b)), (float(c), float(d))) for (a, b), (c, d) in expected}


def test_an_empty_mask_has_no_outline() -> None:
    assert trace_outlines(np.zeros((4, 5), dtype=bool)) == []
