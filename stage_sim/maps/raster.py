"""The static world as a grid at the world ``resolution``: which cells each non-moving model occupies.

Every model outside a position model's subtree is static: floorplan bitmaps, map_server maps, block
polygons and ``boundary`` walls. Each keeps its own cell list with its global z band, ``ranger_return`` and
``obstacle_return``, so that the two questions the simulation asks can be answered per height:

* sensing: which cells does a ray at height h hit, and with what intensity (Stage's 2.5D rule: a ray sees
  a model only if h lies in the model's z band; ``ranger_return < 0`` is transparent);
* collision: which cells block a robot whose body spans the z band [z0, z1] (``obstacle_return 1`` only).

The grid origin is snapped to a multiple of the resolution so that cells line up with Stage's raster,
which is anchored at the world origin.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from stage_sim.maps.body_geometry import body_polygons, global_poses, transform_points
from stage_sim.maps.polygon_raster import fill_polygon, point_cells
from stage_sim.worldfile.description import Model, Pose, WorldDescription
from stage_sim.worldfile.occupancy import FREE, OCCUPIED, OccupancyGrid

# Stage's boundary walls are 0.01 m thick lines along the edges of the model's size box.
BOUNDARY_THICKNESS = 0.01


@dataclass(frozen=True)
class StaticBody:
    """The cells of one static model and what they mean to rays and robots."""

    name: str
    cells: np.ndarray
    z: tuple[float, float]
    ranger_return: float
    obstacle_return: bool


@dataclass
class StaticRaster:
    """All static bodies on one grid (row 0 = smallest y, flat index = row·width + col)."""

    shape: tuple[int, int]
    resolution: float
    origin_xy: tuple[float, float]
    bodies: list[StaticBody]
    _cache: dict = field(default_factory=dict, repr=False)

    def sensing_layer(self, height: float) -> tuple[np.ndarray, np.ndarray]:
        """(occupied, intensity) grids for rays at ``height``."""
        key = ("sense", round(height, 9))
        if key not in self._cache:
            occupied = np.zeros(self.shape[0] * self.shape[1], dtype=bool)
            intensity = np.zeros(occupied.shape, dtype=np.float32)
            for body in self.bodies:
                if body.ranger_return >= 0 and body.z[0] <= height <= body.z[1]:
                    occupied[body.cells] = True
                    intensity[body.cells] = body.ranger_return
            self._cache[key] = (occupied.reshape(self.shape), intensity.reshape(self.shape))
        return self._cache[key]

    def collision_layer(self, z_low: float, z_high: float) -> np.ndarray:
        """Cells that block a body spanning [z_low, z_high]."""
        key = ("collide", round(z_low, 9), round(z_high, 9))
        if key not in self._cache:
            blocked = np.zeros(self.shape[0] * self.shape[1], dtype=bool)
            for body in self.bodies:
                if body.obstacle_return and body.z[0] < z_high and body.z[1] > z_low:
                    blocked[body.cells] = True
            self._cache[key] = blocked.reshape(self.shape)
        return self._cache[key]

    @property
    def occupied(self) -> np.ndarray:
        """Cells occupied by any static body, whatever its height or flags."""
        if "any" not in self._cache:
            occupied = np.zeros(self.shape[0] * self.shape[1], dtype=bool)
            for body in self.bodies:
                occupied[body.cells] = True
            self._cache["any"] = occupied.reshape(self.shape)
        return self._cache["any"]

    @property
    def occupied_cell_count(self) -> int:
        """How many cells some static body occupies."""
        return int(self.occupied.sum())

    def obstacle_extent(self) -> tuple[float, float, float, float] | None:
        """World bounding box (xmin, ymin, xmax, ymax) of the occupied cells, None for an empty world."""
        rows, cols = np.nonzero(self.occupied)
        if rows.size == 0:
            return None
        x0, y0 = self.origin_xy
        res = self.resolution
        return (x0 + cols.min() * res, y0 + rows.min() * res, x0 + (cols.max() + 1) * res, y0 + (rows.max() + 1) * res)

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
    poses = global_poses(description)
    static = _static_models(description)
    shapes = [_world_shape(model, poses[id(model)]) for model in static]
    low, high = _extent(shapes, keep_inside or [])
    origin = (math.floor(low[0] / resolution) * resolution, math.floor(low[1] / resolution) * resolution)
    shape = (math.ceil((high[1] - origin[1]) / resolution) + 1, math.ceil((high[0] - origin[0]) / resolution) + 1)
    bodies = []
    for model, (polygons, image) in zip(static, shapes, strict=True):
        top = poses[id(model)].z
        for points, z in polygons:
            cells = fill_polygon(points, resolution, origin, shape)
            bodies.append(_body(model, cells, (top + z[0], top + z[1])))
        if image is not None:
            mask, pixel_size, frame = image
            cells = _image_cells(mask, pixel_size, frame, resolution, origin, shape)
            bodies.append(_body(model, cells, (top, top + model.size[2])))
    return StaticRaster(shape=shape, resolution=resolution, origin_xy=origin, bodies=bodies)


def _body(model: Model, cells: np.ndarray, z: tuple[float, float]) -> StaticBody:
    return StaticBody(model.name, cells, z, model.ranger_return, model.obstacle_return)


def _static_models(description: WorldDescription) -> list[Model]:
    found: list[Model] = []

    def visit(model: Model, inside_robot: bool) -> None:
        if is_static(model, inside_robot):
            found.append(model)
        for child in model.children:
            visit(child, inside_robot or model.type == "position")

    for top in description.models:
        visit(top, False)
    return found


# A model's world geometry: polygons (world xy, local z band) and an optional image placement
# (mask with row 0 at the bottom, (pixel width, pixel height), world pose of the image's lower-left corner).
_Image = tuple[np.ndarray, tuple[float, float], Pose]
_Shape = tuple[list[tuple[np.ndarray, tuple[float, float]]], _Image | None]


def _world_shape(model: Model, pose: Pose) -> _Shape:
    body_frame = pose.compose(Pose(model.origin.x, model.origin.y, 0.0, model.origin.yaw))
    polygons = []
    if model.bitmap is None:
        polygons = [(transform_points(p.points, pose), p.z) for p in body_polygons(model)]
    if model.boundary:
        hx, hy, t = model.size[0] / 2, model.size[1] / 2, BOUNDARY_THICKNESS
        walls = ((-hx, -hy, hx, -hy + t), (-hx, hy - t, hx, hy), (-hx, -hy, -hx + t, hy), (hx - t, -hy, hx, hy))
        for x0, y0, x1, y1 in walls:
            box = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
            polygons.append((transform_points(box, body_frame), (0.0, model.size[2])))
    return polygons, _image_placement(model, body_frame)


def _image_placement(model: Model, body_frame: Pose) -> _Image | None:
    bitmap = model.bitmap
    if bitmap is None:
        return None
    if bitmap.grid is not None:
        grid = bitmap.grid
        ox, oy, oyaw = grid.origin
        return grid.occupied, (grid.resolution, grid.resolution), body_frame.compose(Pose(ox, oy, 0.0, oyaw))
    rows, cols = np.nonzero(bitmap.occupied)
    if rows.size == 0:
        return None
    cropped = bitmap.occupied[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1][::-1]
    sx, sy = model.size[0], model.size[1]
    pixel = (sx / cropped.shape[1], sy / cropped.shape[0])
    return cropped, pixel, body_frame.compose(Pose(-sx / 2, -sy / 2))


def _image_corners(image: _Image) -> np.ndarray:
    mask, (pw, ph), frame = image
    w, h = mask.shape[1] * pw, mask.shape[0] * ph
    return transform_points(np.array([[0, 0], [w, 0], [w, h], [0, h]], dtype=float), frame)


def _extent(shapes: list[_Shape], discs: list[tuple[float, float, float]]) -> tuple[np.ndarray, np.ndarray]:
    points = [p for polygons, _ in shapes for p, _ in polygons]
    points += [_image_corners(image) for _, image in shapes if image is not None]
    points += [np.array([[x - r, y - r], [x + r, y + r]]) for x, y, r in discs]
    if not points:
        return np.zeros(2), np.ones(2)
    stacked = np.concatenate(points)
    return stacked.min(axis=0), stacked.max(axis=0)


def _image_cells(
    mask: np.ndarray,
    pixel_size: tuple[float, float],
    frame: Pose,
    resolution: float,
    origin: tuple[float, float],
    shape: tuple[int, int],
) -> np.ndarray:
    """Cells covered by occupied image pixels: cell centres that fall on an occupied pixel (no holes when
    cells are smaller than pixels) plus the cells of occupied pixel centres (no pixel lost when larger)."""
    pw, ph = pixel_size
    pix_rows, pix_cols = np.nonzero(mask)
    centres = np.stack([(pix_cols + 0.5) * pw, (pix_rows + 0.5) * ph], axis=1)
    scattered = point_cells(transform_points(centres, frame), resolution, origin, shape)
    corners = _image_corners((mask, pixel_size, frame))
    c0, r0 = np.maximum(np.floor((corners.min(axis=0) - origin) / resolution).astype(int), 0)
    c1, r1 = np.minimum(np.ceil((corners.max(axis=0) - origin) / resolution).astype(int), (shape[1], shape[0]))
    gathered = np.empty(0, dtype=np.int64)
    if c1 > c0 and r1 > r0:
        cols, rows = np.meshgrid(np.arange(c0, c1), np.arange(r0, r1))
        world = np.stack([origin[0] + (cols + 0.5) * resolution, origin[1] + (rows + 0.5) * resolution], axis=-1)
        dx, dy = world[..., 0] - frame.x, world[..., 1] - frame.y
        c, s = math.cos(frame.yaw), math.sin(frame.yaw)
        pc = np.floor((c * dx + s * dy) / pw).astype(np.int64)
        pr = np.floor((-s * dx + c * dy) / ph).astype(np.int64)
        valid = (pc >= 0) & (pc < mask.shape[1]) & (pr >= 0) & (pr < mask.shape[0])
        hit = np.zeros(valid.shape, dtype=bool)
        hit[valid] = mask[pr[valid], pc[valid]]
        gathered = (rows[hit] * shape[1] + cols[hit]).astype(np.int64)
    return np.unique(np.concatenate([gathered, scattered[scattered >= 0]]))
