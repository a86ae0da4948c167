"""The compiled ray caster: :class:`~stage_sim.sensing.raycast.GridRayCaster`'s interface on numba kernels.

Same inputs, same :class:`~stage_sim.sensing.raycast.CastResult`, bit for bit (``tests/sensing``); the
cosines and sines of the angles come from the very numpy calls the reference makes, and the kernel computes
the rest of Stage's per-ray constants (:class:`~stage_sim.sensing.stage_walk.WalkRays`) operation for operation.

Memory: the static layer's bit rows and columns, 264 B per tile (only the world's regions holding a cell at
this height: :mod:`stage_sim.maps.tiles`), the tile grid's region index (4 B per region) shared with the
world, the stop map (1 B per region and its margin, :mod:`stage_sim.sensing.stop_map`) and the robot layer
(:class:`~stage_sim.sensing.robot_layer.RobotLayer`).
"""

from __future__ import annotations

import numpy as np

from stage_sim.backend import announce_compilation, set_threads
from stage_sim.maps.tiles import TileLayer
from stage_sim.sensing import traversal
from stage_sim.sensing.raycast import CastResult
from stage_sim.sensing.robot_layer import CompiledRobotLayer
from stage_sim.sensing.stage_walk import ray_arguments, static_layer
from stage_sim.sensing.stop_map import StopMap

#: Rays from which a cast on more than one thread runs the parallel loop.
PARALLEL_RAYS = 1024
_NONE = np.zeros(0)  # an absent jitter or trigonometry cache
_NO_REGIONS = np.zeros(0, dtype=np.int64)  # no robot layer's regions


class NumbaRayCaster:
    """Stage's ray walk against one static occupancy layer (one ray height), compiled.

    ``occupied``: the layer in tiles, or a dense (H, W) grid; ``blocks`` (dense only): cells holding a
    block of any model at any height (they decide Stage's empty regions), default ``occupied``."""

    def __init__(self, occupied: np.ndarray | TileLayer, resolution: float, origin_xy: tuple[float, float],
                 threads: int = 1, blocks: np.ndarray | None = None):
        if not resolution > 0:
            raise ValueError("resolution must be positive")
        announce_compilation(traversal.cast_serial)
        layer = static_layer(occupied, resolution, origin_xy, blocks)
        self.resolution = float(resolution)
        self.origin_xy = (float(origin_xy[0]), float(origin_xy[1]))
        self.height, self.width = layer.grid.shape
        self.threads = threads
        self._grid = layer.grid
        rows, cols, rows_used, cols_used = bit_masks(layer)
        self._world = (rows, cols, layer.tile_of_slot, layer.grid.slots, rows_used, cols_used)
        self._place = np.append(layer.grid.place, self.width)
        self._stops = StopMap(layer.grid.slots)
        self._no_robots = (np.full((1, 1), -1, dtype=np.int32), np.full((1, 1, 1), -1, dtype=np.int32),
                           np.zeros((1, 1), dtype=np.uint32), np.zeros((1, 1), dtype=np.uint32),
                           np.zeros(1, dtype=np.uint32), np.zeros(1, dtype=np.uint32), np.full(1, -1, dtype=np.int32))

    def robot_layer(self) -> CompiledRobotLayer:
        """An empty robot layer for this caster's grid."""
        return CompiledRobotLayer(self._grid)

    def cast(
        self,
        origins_xy: np.ndarray,
        angles: np.ndarray,
        max_ranges: np.ndarray | float,
        owners: np.ndarray | None = None,
        robots: CompiledRobotLayer | None = None,
    ) -> CastResult:
        """Cast N rays; ``owners[i]`` is the robot that ray i belongs to (−1: none)."""
        xy, ang, rmax, own = ray_arguments(origins_xy, angles, max_ranges, owners)
        n = xy.shape[0]
        ranges = np.empty(n)
        every = np.arange(n)
        cell, hit_robot = self.cast_into(np.ascontiguousarray(xy), every, np.zeros(n), ang, rmax, own, robots, every,
                                         ranges)
        return CastResult(ranges=ranges, hit_cell=cell, hit_robot=hit_robot)

    def walk_arguments(self, longest: float) -> tuple[tuple, np.ndarray, np.ndarray, int, float]:
        """What :func:`~stage_sim.sensing.traversal.cast_serial` reads of this caster for rays of up to
        ``longest`` metres, as :meth:`cast_into` gives it: (world, place, stop map, its margin, cells per metre)."""
        stops, pad = self._stops.fitted(longest / self.resolution)
        return self._world, self._place, stops, pad, 1.0 / self.resolution

    def cast_into(
        self, origins: np.ndarray, origin_of: np.ndarray, heading: np.ndarray, local: np.ndarray, rmax: np.ndarray,
        owners: np.ndarray, robots: CompiledRobotLayer | None, out_at: np.ndarray, out: np.ndarray,
        jitter: np.ndarray = _NONE, trig: tuple[np.ndarray, np.ndarray, np.ndarray] = (_NONE, _NONE, _NONE),
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`cast` as the simulation calls it, with no copies: ray i starts at ``origins[origin_of[i]]``
        (every beam of a ranger from one point) at angle ``heading[origin_of[i]] + local[i]`` (plus
        ``jitter[out_at[i]]`` when given), and its range is written to ``out[out_at[i]]``. ``trig``: the angle,
        cos and sin of each ``out_at`` slot's last cast (NaN angles at first), which the kernel keeps and
        reuses for beams whose angle did not change. Returns (hit cell, hit robot) per ray. Arrays: int64
        indices, float64 values, C-contiguous."""
        n = owners.size
        layer = self._no_robots if robots is None else robots.tables
        flags = (robots is not None, robots is not None and robots.active)
        marked = _NO_REGIONS if robots is None else robots.marked
        stops, pad = self._stops.fitted(float(rmax.max(initial=0.0)) / self.resolution)
        cell = np.empty(n, dtype=np.int64)
        hit_robot = np.empty(n, dtype=np.int32)
        args = (self._world, layer, flags, self._place, stops, pad, marked, origins, origin_of, heading, local, jitter,
                trig, rmax, 1.0 / self.resolution, owners, out_at, out, cell, hit_robot)
        if self.threads > 1 and n > PARALLEL_RAYS:
            set_threads(self.threads)
            traversal.cast_parallel(*args)
        else:
            traversal.cast_serial(*args)
        return cell, hit_robot


def bit_masks(layer: TileLayer) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The layer's tiles as the compiled walk reads them: (T, 32) uint32 row masks (bit x of row y: cell (y,
    x)), column masks (bit y of column x), and per tile a uint32 of the rows (columns) holding a cell, which
    let the walk cross empty rows (columns) at once. Computed the first time only and kept with the layer
    (the casters of two heights that see the same cells share them)."""
    if "bit_masks" not in layer.derived:
        bits = np.ascontiguousarray(layer.bits)
        rows = bits.view("<u4").reshape(bits.shape[0], bits.shape[1]).astype(np.uint32)
        cols, rows_used, cols_used = np.empty_like(rows), np.empty(len(rows), np.uint32), np.empty(len(rows), np.uint32)
        traversal.tile_masks(rows, cols, rows_used, cols_used)
        layer.derived["bit_masks"] = (rows, cols, rows_used, cols_used)
    return layer.derived["bit_masks"]
