"""The static world as a grid at the world ``resolution``: which cells each non-moving model occupies.

Every model outside a position model's subtree is static: floorplan bitmaps, map_server maps, block
polygons and ``boundary`` walls. Each keeps its own cells with its global z band, ``ranger_return`` and
``obstacle_return``, so that the two questions the simulation asks can be answered per height:

* sensing: which cells does a ray at height h hit, and with what intensity (Stage's 2.5D rule: a ray sees
  a model only if h lies in the model's z band; ``ranger_return < 0`` is transparent);
* collision: which cells block a robot whose body spans the z band [z0, z1] (``obstacle_return 1`` only).

Both use Stage's raster (:attr:`StaticBody.outline`): the polygon *edges* only, each vertex floored to its
cell and each edge walked cell by cell (:func:`~stage_sim.maps.polygon_raster.edge_cells`), so a cell that
an edge merely touches is occupied and the inside of a thick obstacle is empty, as in Stage. A second,
filled layer (:attr:`StaticBody.cells`: outline plus the cells whose centre is inside) is what a map of
the world shows (``/map``, pictures, coverage statistics); it never changes a scan or a collision.

The grid's cells are Stage's cells: its origin is a whole number of cells from the world origin. The grid
is virtual (the bounding box of the static world and the robots' start discs): nothing is allocated per
cell of it. Each body keeps the sorted flat indices of its outline cells (8 B per cell); the layers the
simulation asks for are built from them straight into tiles of 32 × 32 cells where a layer has a cell
(:mod:`stage_sim.maps.tiles`: 4 B per 1024 cells of the box for the region index, 128 B per tile and
layer). The filled footprints are made only when a map is asked for.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from functools import cached_property
from itertools import groupby

import numpy as np

from stage_sim.maps.body_geometry import body_frame, body_shape, transform_points, tree_poses
from stage_sim.maps.polygon_raster import edge_cells, fill_cells, vertex_cells
from stage_sim.maps.tiles import DENSE_CELL_LIMIT, CellValues, TileGrid, TileLayer, WorldTooLargeError, unique_sorted
from stage_sim.worldfile.description import Model, WorldDescription
from stage_sim.worldfile.occupancy import FREE, OCCUPIED, OccupancyGrid


@dataclass(frozen=True)
class StaticBody:
    """One shape of a static model (a block, a wall, an image's outlines) and what it means to rays and robots.

    ``outline`` holds the sorted flat indices of Stage's raster cells (edges only), what rays and bodies hit
    (8 B per cell); :attr:`cells` the filled footprint (outline and inside), what a map shows, made only
    when a map is asked for.
    """

    name: str
    outline: np.ndarray
    z: tuple[float, float]
    ranger_return: float
    obstacle_return: bool
    polygons: list[np.ndarray] = field(repr=False, compare=False)
    frame: tuple[float, tuple[float, float], tuple[int, int]] = field(repr=False, compare=False)
    """(resolution, origin, shape) of the grid the cells index."""

    def blocks(self, z_low: float, z_high: float) -> bool:
        """Whether this body stops a robot whose body spans [z_low, z_high]."""
        return self.obstacle_return and self.z[0] < z_high and self.z[1] > z_low

    @cached_property
    def cells(self) -> np.ndarray:
        """Sorted flat cells of the filled footprint: the outline and the cells whose centre is inside."""
        resolution, origin, shape = self.frame
        points = np.concatenate(self.polygons)
        span = (points.max(axis=0) - points.min(axis=0)) / resolution + 2
        if span[0] * span[1] > DENSE_CELL_LIMIT:
            raise WorldTooLargeError(
                f"the filled footprint of {self.name!r} spans {span[0]:.0f} x {span[1]:.0f} cells (the limit of a "
                f"map is {DENSE_CELL_LIMIT / 1e6:.0f} M cells): use a coarser resolution")
        return unique_sorted(np.concatenate([self.outline, fill_cells(self.polygons, resolution, origin, shape)]))


@dataclass
class StaticRaster:
    """All static bodies on one virtual grid (row 0 = smallest y, flat index = row·width + col), stored in
    tiles (:mod:`stage_sim.maps.tiles`): nothing here costs memory in proportion to the grid's area, but the
    dense copies a picture of the whole world asks for (:meth:`sensing_layer`, :meth:`collision_layer`,
    :attr:`occupied`, :meth:`to_occupancy_grid`), refused past :data:`~stage_sim.maps.tiles.DENSE_CELL_LIMIT`."""

    shape: tuple[int, int]
    resolution: float
    origin_xy: tuple[float, float]
    bodies: list[StaticBody]
    _cache: dict = field(default_factory=dict, repr=False)
    extends: StaticRaster | None = field(default=None, repr=False, compare=False)
    """The raster this one adds bodies to, on the same grid (:func:`with_models`): its tiles, once made, are
    extended rather than made again."""

    @cached_property
    def grid(self) -> TileGrid:
        """The tile grid: Stage's regions, a slot for each one holding a block of any body at any height."""
        base = self.extends
        if base is not None and "grid" in base.__dict__:
            return base.grid.with_blocks(self._outlines(range(len(base.bodies), len(self.bodies))))
        return TileGrid.build(self.shape, self.resolution, self.origin_xy, self._outlines(range(len(self.bodies))))

    def _outlines(self, chosen: Iterable[int]) -> np.ndarray:
        """The outline cells of the bodies ``chosen``, end to end."""
        return np.concatenate([self.bodies[i].outline for i in chosen] or [np.zeros(0, dtype=np.int64)])

    def sensing_tiles(self, height: float) -> tuple[TileLayer, CellValues]:
        """The cells rays at ``height`` hit, in tiles, and their intensity (a later body over an earlier one).

        Heights that see the same bodies get the very same objects (one caster serves them all)."""
        seen = tuple(i for i, body in enumerate(self.bodies)
                     if body.ranger_return >= 0 and body.z[0] <= height <= body.z[1])
        key = ("sense", seen)
        if key not in self._cache:
            bodies = [self.bodies[i] for i in seen]
            flat = np.concatenate([body.outline for body in bodies] or [np.zeros(0, dtype=np.int64)])
            values = np.concatenate([np.full(body.outline.size, body.ranger_return) for body in bodies]
                                    or [np.zeros(0)])
            self._cache[key] = (self._layer(seen, flat), CellValues.last_wins(flat, values))
        return self._cache[key]

    def collision_tiles(self, z_low: float, z_high: float) -> TileLayer:
        """The cells that block a body spanning [z_low, z_high], in tiles (the very layer rays see when the same
        bodies block as are seen: an episode's world makes it once, not twice)."""
        return self._layer(tuple(i for i, body in enumerate(self.bodies) if body.blocks(z_low, z_high)))

    def _layer(self, chosen: tuple[int, ...], flat: np.ndarray | None = None) -> TileLayer:
        """The outline cells of the bodies ``chosen`` (their ``flat`` outlines end to end, when at hand) in
        tiles, made once per set of bodies (layers are never written to)."""
        key = ("layer", chosen)
        if key not in self._cache:
            base = self.extends
            kept = chosen if base is None else tuple(i for i in chosen if i < len(base.bodies))
            if base is not None and ("layer", kept) in base._cache:
                added = self._outlines(chosen[len(kept):])  # the bodies after the base's
                self._cache[key] = base._cache[("layer", kept)].with_cells(self.grid, added)
            else:
                flat = self._outlines(chosen) if flat is None else flat
                self._cache[key] = TileLayer.from_cells(self.grid, unique_sorted(flat))
        return self._cache[key]

    def sensing_layer(self, height: float) -> tuple[np.ndarray, np.ndarray]:
        """(occupied, intensity) dense grids for rays at ``height`` (a picture: small worlds only)."""
        self.grid.check_dense("a dense sensing layer")
        layer, intensity = self.sensing_tiles(height)
        values = np.zeros(self.shape[0] * self.shape[1], dtype=np.float32)
        cells = layer.cells()
        values[cells] = intensity.at(cells)
        return layer.dense(), values.reshape(self.shape)

    def collision_layer(self, z_low: float, z_high: float) -> np.ndarray:
        """Dense grid of the cells that block a body spanning [z_low, z_high] (small worlds only)."""
        return self.collision_tiles(z_low, z_high).dense("a dense collision layer")

    def filled_collision_layer(self, z_low: float, z_high: float) -> np.ndarray:
        """Dense grid of the filled footprints of the bodies that block a body spanning [z_low, z_high]: where a
        robot may not stand (contacts see only outlines, as in Stage, so a robot placed inside a block would
        never notice it). Small worlds only."""
        self.grid.check_dense("a dense filled collision layer")
        filled = np.zeros(self.shape[0] * self.shape[1], dtype=bool)
        for body in self.bodies:
            if body.blocks(z_low, z_high):
                filled[body.cells] = True
        return filled.reshape(self.shape)

    @property
    def occupied(self) -> np.ndarray:
        """Cells of any static body's filled footprint, whatever its height or flags (a map, not the raster)."""
        if "any" not in self._cache:
            self.grid.check_dense("a map of the world")
            occupied = np.zeros(self.shape[0] * self.shape[1], dtype=bool)
            for body in self.bodies:
                occupied[body.cells] = True
            self._cache["any"] = occupied.reshape(self.shape)
        return self._cache["any"]

    def map_labels(self, max_cells: int = DENSE_CELL_LIMIT) -> tuple[np.ndarray, int]:
        """A picture of the static world: per pixel 0 (free) or k (the k-th body, later bodies on top), and
        how many cells a pixel side spans. One pixel per cell with the filled footprints when the grid has at
        most ``max_cells`` cells; else one pixel per ``step`` × ``step`` cells holding any outline cell (the
        filled footprint of a world that large is never made)."""
        h, w = self.shape
        step = 1 if h * w <= max_cells else int(np.ceil(np.sqrt(h * w / max_cells)))
        labels = np.zeros((-(-h // step), -(-w // step)), dtype=np.int32)
        for k, body in enumerate(self.bodies, start=1):
            rows, cols = np.divmod(body.cells if step == 1 else body.outline, w)
            labels[rows // step, cols // step] = k
        return labels, step

    @property
    def occupied_cell_count(self) -> int:
        """How many cells the filled footprints cover."""
        return int(self.occupied.sum())

    def to_occupancy_grid(self) -> OccupancyGrid:
        """The static world as a nav_msgs-style grid (100 occupied, 0 free) for ``/map``."""
        values = np.where(self.occupied, OCCUPIED, FREE).astype(np.int8)
        return OccupancyGrid(values=values, resolution=self.resolution, origin=(*self.origin_xy, 0.0))


def is_static(model: Model, inside_robot: bool) -> bool:
    """Models that never move: anything not a position model nor inside one."""
    return not inside_robot and model.type != "position"


def build_static_raster(
    description: WorldDescription, keep_inside: list[tuple[float, float, float]] | None = None
) -> StaticRaster:
    """Rasterise every static model of the world; ``keep_inside`` adds (x, y, radius) discs to the extent."""
    resolution = description.settings.resolution
    shapes = _world_shapes(description.models)
    vertices = [vertex_cells(part.points, resolution) for part in shapes]
    outlines = [edge_cells([v]) for v in vertices]
    corners = [np.zeros((0, 2), dtype=np.int64), *vertices, *outlines]
    for x, y, r in keep_inside or []:
        corners.append(vertex_cells(np.array([[x - r, y - r], [x + r, y + r]]), resolution))
    stacked = np.concatenate(corners)
    low, high = (stacked.min(axis=0), stacked.max(axis=0)) if len(stacked) else (np.zeros(2, int), np.ones(2, int))
    frame = _frame(low, high, resolution)
    bodies = _static_bodies(shapes, outlines, low, frame)
    return StaticRaster(shape=frame[2], resolution=resolution, origin_xy=frame[1], bodies=bodies)


def _frame(low: np.ndarray, high: np.ndarray,
           resolution: float) -> tuple[float, tuple[float, float], tuple[int, int]]:
    """(resolution, origin, shape) of the grid whose first and last cells are ``low`` and ``high`` (col, row)."""
    shape = (int(high[1] - low[1]) + 1, int(high[0] - low[0]) + 1)
    return resolution, (float(low[0]) * resolution, float(low[1]) * resolution), shape


def polygon_edges(vertices: np.ndarray) -> np.ndarray:
    """The cells Stage marks for one closed polygon of vertex cells (:func:`edge_cells` of it alone)."""
    return edge_cells([vertices])


def with_models(raster: StaticRaster, models: list[Model],
                trace: Callable[[np.ndarray], np.ndarray] = polygon_edges) -> StaticRaster:
    """The raster of a world that is ``raster``'s with the top-level ``models`` appended (an episode's
    obstacles): the one :func:`build_static_raster` makes of that world, with only the new bodies traced, each
    polygon by ``trace`` (:func:`polygon_edges`, or its compiled twin). While every new cell lies on the grid the
    bodies already rasterised are shared and the new raster extends the old one's tiles; a new cell off the grid
    grows it (to the box a raster of the whole world would have) and the old outlines are moved onto it."""
    shapes = _world_shapes(models)
    vertices = [vertex_cells(part.points, raster.resolution) for part in shapes]
    outlines = [trace(v) for v in vertices]
    resolution = raster.resolution
    low = np.array([round(raster.origin_xy[0] / resolution), round(raster.origin_xy[1] / resolution)])
    high = low + np.array(raster.shape[::-1]) - 1
    stacked = np.concatenate([np.zeros((0, 2), dtype=np.int64), *vertices, *outlines])
    if len(stacked) and ((stacked.min(axis=0) < low).any() or (stacked.max(axis=0) > high).any()):
        grown_low, grown_high = np.minimum(low, stacked.min(axis=0)), np.maximum(high, stacked.max(axis=0))
        frame = _frame(grown_low, grown_high, resolution)
        kept = [_moved(body, low - grown_low, raster.shape[1], frame) for body in raster.bodies]
        bodies = [*kept, *_static_bodies(shapes, outlines, grown_low, frame)]
        return StaticRaster(shape=frame[2], resolution=resolution, origin_xy=frame[1], bodies=bodies)
    frame = (resolution, raster.origin_xy, raster.shape)
    bodies = [*raster.bodies, *_static_bodies(shapes, outlines, low, frame)]
    return StaticRaster(shape=raster.shape, resolution=resolution, origin_xy=raster.origin_xy, bodies=bodies,
                        extends=raster)


def _moved(body: StaticBody, shift: np.ndarray, width: int,
           frame: tuple[float, tuple[float, float], tuple[int, int]]) -> StaticBody:
    """``body`` on a grown grid (``frame``) whose cell ``-shift`` (columns, rows) was the old grid's (0, 0),
    ``width`` the old grid's columns: its outline cells keep their row-major order, so they stay sorted. Its
    filled footprint, when made, moves with it: the same world cells, not filled again (a free space of every
    episode whose obstacles grow the grid asked for the arena's walls' footprints anew, 3 ms of its reset)."""

    def move(flat: np.ndarray) -> np.ndarray:
        rows, cols = np.divmod(flat, width)
        return (rows + shift[1]) * frame[2][1] + cols + shift[0]

    moved = replace(body, outline=move(body.outline), frame=frame)
    if "cells" in body.__dict__:
        moved.__dict__["cells"] = move(body.cells)  # the cached_property's slot: what reading it would store
    return moved


def _static_bodies(
    shapes: list[_Placed], outlines: list[np.ndarray], low: np.ndarray,
    frame: tuple[float, tuple[float, float], tuple[int, int]],
) -> list[StaticBody]:
    """One body per shape (the polygons of a model's shape group), its outline cells on the grid whose world
    cell ``low`` is its (0, 0) and whose ``frame`` is (resolution, origin, shape)."""
    width = frame[2][1]
    bodies = []
    for _, members in groupby(zip(shapes, outlines, strict=True), key=lambda item: (id(item[0].model), item[0].group)):
        parts = list(members)
        shape_of, cells = parts[0][0], np.concatenate([cells for _, cells in parts]) - low
        outline = unique_sorted(cells[:, 1] * width + cells[:, 0])
        model = shape_of.model
        bodies.append(StaticBody(model.name, outline, shape_of.z, model.ranger_return, model.obstacle_return,
                                 [part.points for part, _ in parts], frame))
    return bodies


def static_outline_summary(description: WorldDescription) -> dict[str, object]:
    """Static models, their polygons and the extent those cover, from geometry alone (no raster is built).

    What ``stage_sim inspect`` reports: a world of any size and resolution is summarised in the time its
    outlines take to trace, never in memory proportional to its area."""
    shapes = _world_shapes(description.models)
    points = np.concatenate([part.points for part in shapes]) if shapes else np.zeros((0, 2))
    extent = [*points.min(axis=0), *points.max(axis=0)] if len(points) else None
    models = len({id(part.model) for part in shapes})
    return {"models": models, "polygons": len(shapes), "extent": [float(v) for v in extent] if extent else None}


@dataclass(frozen=True)
class _Placed:
    """One polygon of a static model in world coordinates, with its global z band and shape group."""

    model: Model
    points: np.ndarray
    z: tuple[float, float]
    group: int


def _world_shapes(models: list[Model]) -> list[_Placed]:
    """Every static polygon of the top-level ``models`` and their subtrees placed in the world, the polygons
    of one shape next to each other."""
    poses = tree_poses(models)
    placed = []
    for model in _static_models(models):
        pose = poses[id(model)]
        frame = body_frame(model, pose)
        top = pose.z + model.origin.z
        for polygon in sorted(body_shape(model), key=lambda p: p.group):
            z = (top + polygon.z[0], top + polygon.z[1])
            placed.append(_Placed(model, transform_points(polygon.points, frame), z, polygon.group))
    return placed


def _static_models(models: list[Model]) -> list[Model]:
    found: list[Model] = []

    def visit(model: Model, inside_robot: bool) -> None:
        if is_static(model, inside_robot):
            found.append(model)
        for child in model.children:
            visit(child, inside_robot or model.type == "position")

    for top in models:
        visit(top, False)
    return found
