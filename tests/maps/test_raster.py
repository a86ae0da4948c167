"""Stage's raster of static bodies: vertices floored to cells, edges walked cell by cell, insides empty."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from PIL import Image

from stage_sim.maps.body_geometry import body_shape
from stage_sim.maps.polygon_raster import edge_cells, vertex_cells
from stage_sim.maps.raster import build_static_raster
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text


def stage_map_poly(vertices: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """World::MapPoly of libstage/world.cc, transcribed loop for loop (the reference)."""
    cells = []
    for i, (x, y) in enumerate(vertices):
        ex, ey = vertices[(i + 1) % len(vertices)]
        dx, dy = ex - x, ey - y
        sx, sy = (dx > 0) - (dx < 0), (dy > 0) - (dy < 0)
        ax, ay = abs(dx), abs(dy)
        exy, n = ay - ax, ax + ay
        while n:
            cells.append((x, y))
            if exy < 0:
                x, exy = x + sx, exy + 2 * ay
            else:
                y, exy = y + sy, exy - 2 * ax
            n -= 1
    return cells


def cells_of(raster, flat: np.ndarray) -> set[tuple[int, int]]:
    """(col, row) in Stage's global cells of flat indices of ``raster``."""
    col0, row0 = (round(v / raster.resolution) for v in raster.origin_xy)
    rows, cols = np.divmod(flat, raster.shape[1])
    return {(int(c) + col0, int(r) + row0) for r, c in zip(rows, cols, strict=True)}


def test_an_edge_marks_the_cells_from_its_start_cell_up_to_but_not_its_end_cell() -> None:
    cells = edge_cells([np.array([[0, 0], [3, 1], [0, 1]])])
    # (0,0) → (3,1): the error term starts at 1 − 3 < 0 (x), then 0 (a tie: y), then x, x
    assert [tuple(c) for c in cells[:4].tolist()] == [(0, 0), (1, 0), (1, 1), (2, 1)]
    assert [tuple(c) for c in cells.tolist()] == stage_map_poly([(0, 0), (3, 1), (0, 1)])


def test_edges_within_one_cell_mark_nothing() -> None:
    assert edge_cells([np.array([[4, 4], [4, 4], [4, 4]])]).shape == (0, 2)


def test_edge_cells_match_stages_loop_on_random_polygons() -> None:
    rng = np.random.default_rng(7)
    for _ in range(200):
        polygons = [rng.integers(-30, 30, size=(rng.integers(1, 8), 2)) for _ in range(rng.integers(1, 4))]
        got = [tuple(c) for c in edge_cells(polygons).tolist()]
        assert got == [cell for p in polygons for cell in stage_map_poly([tuple(v) for v in p.tolist()])]


def test_vertices_are_floored_to_the_cell_they_fall_in_counted_from_the_world_origin() -> None:
    points = np.array([[1.0, 0.99999], [-0.05, 0.25]])
    assert vertex_cells(points, 0.1).tolist() == [[10, 9], [-1, 2]]


BOX_WORLD = """
resolution 0.1
model( name "box" size [1 1 1] pose [2 2 0 0] color "black" )
"""


def test_a_block_is_its_outline_a_cell_an_edge_touches_is_occupied_and_the_inside_is_empty() -> None:
    raster = build_static_raster(load_world_text(BOX_WORLD, "box.world"))
    (box,) = raster.bodies
    # the box spans x, y in [1.5, 2.5]: vertices in cells 15 and 25; the edges at 2.5 lie on the lower
    # border of cells 25, which are occupied (Stage's walls reach 2.6 there)
    ring = {(c, r) for c in range(15, 26) for r in range(15, 26) if c in (15, 25) or r in (15, 25)}
    assert cells_of(raster, box.outline) == ring
    sensing = raster.sensing_layer(0.5)[0]
    assert cells_of(raster, np.flatnonzero(sensing)) == ring
    assert cells_of(raster, np.flatnonzero(raster.collision_layer(0.0, 0.2))) == ring
    # the filled footprint (a map, not the raster) also holds the inside
    inside = {(c, r) for c in range(16, 25) for r in range(16, 25)}
    assert cells_of(raster, box.cells) == ring | inside
    assert raster.occupied.sum() == 11 * 11


def test_the_grid_origin_is_a_whole_number_of_cells_from_the_world_origin() -> None:
    raster = build_static_raster(load_world_text(BOX_WORLD.replace("pose [2 2 0 0]", "pose [-2.03 7.01 0 0]"), "b.w"))
    col0, row0 = (v / raster.resolution for v in raster.origin_xy)
    assert math.isclose(col0, round(col0)) and math.isclose(row0, round(row0))
    (box,) = raster.bodies
    x0, y0 = -2.53, 6.51  # lower-left corner of the box
    assert (math.floor(x0 * 10), math.floor(y0 * 10)) in cells_of(raster, box.outline)


def test_a_ray_stops_at_the_outer_cell_an_edge_touches_and_a_laser_inside_sees_the_inner_side() -> None:
    world = BOX_WORLD + """
define laser ranger ( sensor( range [0 5] fov 180 samples 3 ) size [0.05 0.05 0.05] )
position( name "r" size [0.1 0.1 0.1] pose [4.05 2.05 0 180] obstacle_return 0 laser( pose [0 0 0 0] ) )
"""
    sim = Simulation(load_world_text(world, "w.world"), seed=0)
    # facing −x from x = 4.05 at y = 2.05: the east wall's cells are column 25 = [2.5, 2.6); Stage's walk
    # reports the whole cells walked from the origin's cell 40 to it (15), not the true ray's 1.45 m
    assert math.isclose(sim.scans[0][0].ranges[1], 1.5, abs_tol=1e-6)
    sim.set_pose(0, 2.05, 2.05, math.pi)
    sim.step()
    # from inside, facing −x: the west wall's cells are column 15 = [1.5, 1.6): 5 cells from cell 20
    assert math.isclose(sim.scans[0][0].ranges[1], 0.5, abs_tol=1e-6)


def test_a_robot_inside_a_big_obstacle_but_clear_of_its_edges_does_not_collide() -> None:
    # Stage rasterises edges only: a body entirely inside a large block touches no occupied cell (spec §6.3).
    world = BOX_WORLD.replace("size [1 1 1]", "size [3 3 1]") + """
position( name "r" size [0.2 0.2 0.2] pose [2 2 0 0] )
"""
    sim = Simulation(load_world_text(world, "w.world"), seed=0)
    sim.set_velocity(0, 0.2, 0.0, 0.0)
    for _ in range(3):
        sim.step()
    assert not sim.stalled[0] and sim.true_poses[0, 0] > 2.05
    raster = sim.static
    row, col = (int((v - o) / raster.resolution) for v, o in zip((2.0, 2.0), raster.origin_xy[::-1], strict=True))
    assert raster.occupied[row, col]  # the map shows the obstacle there


def write_png(path: Path, rows: list[str]) -> Path:
    pixels = np.array([[0 if c == "#" else 255 for c in row] for row in rows], dtype=np.uint8)
    Image.fromarray(pixels, mode="L").save(path)
    return path


def test_a_bitmap_is_the_outline_of_its_occupied_pixels_scaled_to_the_size(tmp_path: Path) -> None:
    # 4 x 2 pixels, white margin column on the right (trimmed); occupied box 3 x 2 px → size 0.6 x 0.4 m,
    # 0.2 m pixels, centred on (1, 1): x in [0.7, 1.3], y in [0.8, 1.2]; a hole-free 3 x 2 block
    write_png(tmp_path / "m.png", ["###.", "###."])
    world = 'resolution 0.1\nmodel( name "map" size [0.6 0.4 0.5] pose [1 1 0 0] bitmap "m.png" )\n'
    raster = build_static_raster(load_world_text(world, tmp_path / "w.world"))
    (image,) = raster.bodies
    assert image.z == (0.0, 0.5)
    ring = {(c, r) for c in range(7, 14) for r in range(8, 13) if c in (7, 13) or r in (8, 12)}
    assert cells_of(raster, image.outline) == ring


def test_a_rotated_bitmap_is_rasterised_from_its_rotated_vertices(tmp_path: Path) -> None:
    write_png(tmp_path / "m.png", ["##", "##"])
    world = 'resolution 0.1\nmodel( name "map" size [1 1 1] pose [3 3 0 45] bitmap "m.png" )\n'
    description = load_world_text(world, tmp_path / "w.world")
    raster = build_static_raster(description)
    (image,) = raster.bodies
    (outline,) = body_shape(description.models[0])
    c = s = math.sqrt(0.5)
    corners = [(3 + x * c - y * s, 3 + x * s + y * c) for x, y in outline.points]
    expected = stage_map_poly([(math.floor(x * 10), math.floor(y * 10)) for x, y in corners])
    assert cells_of(raster, image.outline) == set(expected)


def test_boundary_adds_thin_walls_inside_the_size_box() -> None:
    world = 'resolution 0.1\nmodel( name "room" size [2 1 0.5] pose [1 0.5 0 0] boundary 1\n' \
            '       block( points 4 point[0] [0 0] point[1] [1 0] point[2] [1 1] point[3] [0 1] z [0 1] ) )\n'
    description = load_world_text(world, "w.world")
    shape = body_shape(description.models[0])
    assert len(shape) == 5  # the block and four walls
    walls = shape[1:]
    for wall in walls:
        extent = wall.points.max(axis=0) - wall.points.min(axis=0)
        assert math.isclose(min(extent), 0.01) and wall.z == (0.0, 0.5)
    low = np.min([w.points.min(axis=0) for w in walls], axis=0)
    high = np.max([w.points.max(axis=0) for w in walls], axis=0)
    assert np.allclose(low, (-1.0, -0.5)) and np.allclose(high, (1.0, 0.5))
