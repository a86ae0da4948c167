"""Robot bodies are rasterised as Stage rasterises blocks, and the compiled raster is the reference's bit for bit.

The per-polygon walk (:func:`~stage_sim.maps.polygon_raster.edge_walk`, compiled for the robots) marks the cells
of the static blocks' raster (:func:`~stage_sim.maps.polygon_raster.edge_cells`), in the same order.
"""

from __future__ import annotations

import numpy as np

from stage_sim.maps.polygon_raster import edge_cells, edge_walk, vertex_cells
from stage_sim.sim.simulation import Simulation
from tests.sim.robot_golden import ROBOTS


def test_edge_walk_marks_the_cells_of_the_static_raster() -> None:
    rng = np.random.default_rng(3)
    for _ in range(200):
        vertices = rng.integers(-40, 40, size=(rng.integers(2, 7), 2))
        out = np.empty((int(np.abs(np.roll(vertices, -1, 0) - vertices).sum()), 2), dtype=np.int64)
        assert edge_walk(vertices, out, 0) == len(out)
        np.testing.assert_array_equal(out, edge_cells([vertices]))


def test_compiled_polygon_outline_is_the_static_rasters_edges() -> None:
    """What an episode's new obstacles are traced with on the compiled kernels (``Backend.trace``)."""
    from stage_sim.sim.body_kernels import polygon_outline

    rng = np.random.default_rng(5)
    for _ in range(300):
        vertices = rng.integers(-60, 60, size=(rng.integers(1, 8), 2))
        np.testing.assert_array_equal(polygon_outline(vertices), edge_cells([vertices]))
    within_one_cell = np.array([[3, 4], [3, 4], [3, 4]])
    assert polygon_outline(within_one_cell).shape == (0, 2) == edge_cells([within_one_cell]).shape


def test_a_box_body_is_its_edges_floored_and_walked_at_the_pose() -> None:
    sim = Simulation.from_world(ROBOTS / "crowd_100.world", seed=0, kernels="numpy")
    cells, owner = sim.build_parts("numpy")[0].raster(sim.start_poses)
    pose = sim.start_poses[0]
    c, s = np.cos(pose[2]), np.sin(pose[2])
    expected = []
    for polygon in sim.robots[0].body:
        world = np.stack([pose[0] + c * polygon[:, 0] - s * polygon[:, 1],
                          pose[1] + s * polygon[:, 0] + c * polygon[:, 1]], axis=1)
        expected.append(edge_cells([vertex_cells(world, 0.02)]))
    walked = np.concatenate(expected)
    col0, row0 = round(sim.static.origin_xy[0] / 0.02), round(sim.static.origin_xy[1] / 0.02)
    flat = (walked[:, 1] - row0) * sim.static.shape[1] + walked[:, 0] - col0
    np.testing.assert_array_equal(cells[owner == 0], flat)


def test_compiled_raster_is_the_reference_bit_for_bit() -> None:
    for world in ("crowd_100.world", "discs_200.world"):
        sim = Simulation.from_world(ROBOTS / world, seed=0, kernels="numpy")
        rng = np.random.default_rng(5)
        poses = sim.start_poses + rng.normal(0, [0.3, 0.3, 2.0], sim.start_poses.shape)
        numpy_cells = sim.build_parts("numpy")[0].raster(poses)
        numba_cells = sim.build_parts("numba")[0].raster(poses)
        for a, b in zip(numpy_cells, numba_cells, strict=True):
            np.testing.assert_array_equal(a, b)
