"""The compiled ray caster: :class:`~stage_sim.sensing.raycast.GridRayCaster`'s interface on numba kernels.

Same inputs, same :class:`~stage_sim.sensing.raycast.CastResult`, bit for bit (``tests/sensing``); the
cosines and sines of the angles come from the very numpy calls the reference makes, and the kernel computes
the rest of Stage's per-ray constants (:class:`~stage_sim.sensing.stage_walk.WalkRays`) operation for operation.

Memory per layer of H × W cells (rooms.world at 0.02 m: 1082 × 1352 = 1.46 M cells):

* free squares, 4 quadrants × uint8: 4 B/cell (5.9 MB);
* robot ids (only once robots are placed), int32: 4 B/cell (5.9 MB), plus two small block grids
  (1/64 of that each);
* Stage's region grid: one bool per 32 × 32 cells.

The numpy reference keeps the same fields (its square fields stored mirrored per quadrant) and builds
them with int32 temporaries.
"""

from __future__ import annotations

import numpy as np

from stage_sim.sensing import traversal
from stage_sim.sensing.kernels import announce_compilation, set_threads
from stage_sim.sensing.raycast import CastResult
from stage_sim.sensing.robot_layer import SEVERAL_ROBOTS, visible_cells
from stage_sim.sensing.stage_walk import WalkGrid, beam_cos_sin, ray_arguments


class RobotCells:
    """Robot footprints on one layer for the compiled caster.

    Same meaning as :class:`~stage_sim.sensing.robot_layer.RobotLayer`: an id per cell, :data:`SEVERAL_ROBOTS`
    where two robots touch; per block, which robot is there (if only one) lets rays skip robot-free space.
    """

    def __init__(self, shape: tuple[int, int], walk_grid: WalkGrid | None = None) -> None:
        self.shape = shape
        self._walk_grid = walk_grid
        self.regions = walk_grid.static_regions if walk_grid is not None else np.zeros((1, 1), dtype=bool)
        self.region_squares = traversal.region_squares(self.regions)
        self.grid = np.full(shape, -1, dtype=np.int32)
        size = 1 << traversal.BLOCK
        self.blocks = np.full((-(-shape[0] // size), -(-shape[1] // size)), -1, dtype=np.int32)
        self._blocks_in_use = self.blocks != -1
        self.block_squares = traversal.square_fields(self._blocks_in_use)
        self._written = np.empty(0, dtype=np.int64)
        self.active = False

    def update(
        self,
        cell_rows: np.ndarray,
        cell_cols: np.ndarray,
        robot_ids: np.ndarray,
        visible: np.ndarray | None = None,
    ) -> None:
        """Replace the footprints: robot ``robot_ids[i]`` covers cell (``cell_rows[i]``, ``cell_cols[i]``).

        Every robot's cells, seen at this height or not, make their regions non-empty (Stage counts blocks)."""
        self.mark_regions(cell_rows, cell_cols)
        rows, cols, ids = visible_cells(cell_rows, cell_cols, robot_ids, self.shape, visible)
        flat = rows * self.shape[1] + cols
        traversal.write_robot_cells(self.grid, self.blocks, self._written, flat, ids.astype(np.int32), SEVERAL_ROBOTS)
        in_use = self.blocks != -1
        if not np.array_equal(in_use, self._blocks_in_use):  # standing or jammed robots keep their blocks
            self._blocks_in_use = in_use
            self.block_squares = traversal.square_fields(in_use)
        self._written = flat
        self.active = flat.size > 0

    def mark_regions(self, cell_rows: np.ndarray, cell_cols: np.ndarray) -> None:
        """Make the regions of these robot cells non-empty (and only those besides the static ones)."""
        if self._walk_grid is None:
            return
        rows, cols, _ = visible_cells(cell_rows, cell_cols, np.zeros(np.size(cell_rows), dtype=np.int64), self.shape,
                                      None)
        regions = self._walk_grid.with_cells(rows, cols)
        if not np.array_equal(regions, self.regions):
            self.regions = regions
            self.region_squares = traversal.region_squares(regions)


class NumbaRayCaster:
    """Stage's ray walk against one static occupancy layer (one ray height), compiled.

    ``blocks``: cells holding a block of any model at any height (they decide Stage's empty regions);
    default ``occupied``."""

    kernels = "numba"

    def __init__(self, occupied: np.ndarray, resolution: float, origin_xy: tuple[float, float], threads: int = 1,
                 blocks: np.ndarray | None = None):
        occ = np.asarray(occupied, dtype=bool)
        if occ.ndim != 2 or occ.size == 0:
            raise ValueError("occupied must be a non-empty 2-D array")
        if not resolution > 0:
            raise ValueError("resolution must be positive")
        announce_compilation(traversal.square_fields, traversal.cast_serial)
        self.occupied = occ
        self.resolution = float(resolution)
        self.origin_xy = (float(origin_xy[0]), float(origin_xy[1]))
        self.height, self.width = occ.shape
        self.threads = threads
        self._squares = traversal.square_fields(occ)
        self._walk_grid = WalkGrid.build(occ if blocks is None else np.asarray(blocks, dtype=bool) | occ,
                                         self.resolution, self.origin_xy)
        self._place = np.array([self._walk_grid.col0, self._walk_grid.row0, self._walk_grid.rcol0,
                                self._walk_grid.rrow0], dtype=np.int64)
        self._no_robots = RobotCells((1, 1), self._walk_grid)

    def robot_layer(self) -> RobotCells:
        """An empty robot layer for this caster's grid."""
        return RobotCells((self.height, self.width), self._walk_grid)

    def cast(
        self,
        origins_xy: np.ndarray,
        angles: np.ndarray,
        max_ranges: np.ndarray | float,
        owners: np.ndarray | None = None,
        robots: RobotCells | None = None,
    ) -> CastResult:
        """Cast N rays; ``owners[i]`` is the robot that ray i belongs to (−1: none)."""
        xy, ang, rmax, own = ray_arguments(origins_xy, angles, max_ranges, owners)
        n = xy.shape[0]
        cosa, sina = beam_cos_sin(ang)
        active = robots is not None and robots.active
        layer = robots if active else self._no_robots
        regions = robots if robots is not None else self._no_robots
        ranges = np.empty(n)
        cell = np.empty(n, dtype=np.int64)
        hit_robot = np.empty(n, dtype=np.int32)
        args = (self._squares, layer.grid, active, layer.blocks, layer.block_squares, regions.regions,
                regions.region_squares, self._place, np.ascontiguousarray(xy), cosa, sina, np.ascontiguousarray(rmax),
                1.0 / self.resolution, own, ranges, cell, hit_robot)
        if self.threads > 1 and n > 1024:
            set_threads(self.threads)
            traversal.cast_parallel(*args)
        else:
            traversal.cast_serial(*args)
        return CastResult(ranges=ranges, hit_cell=cell, hit_robot=hit_robot)

