"""Where model bodies are: Stage's block scaling and the global poses of the model tree.

A body is the model's ``block`` polygons, or the polygons Stage traces from its ``bitmap``
(:func:`~stage_sim.worldfile.bitmap.trace_outlines`), plus four thin walls when ``boundary 1``. All of them
are scaled jointly the way Stage's ``BlockGroup::CalcSize`` does it: the bounding box of their points
becomes the model's ``size`` (x, y) and is centred on the model origin, z values are multiplied by
size.z / (zmax − zmin) of all blocks. A body point q then sits at ``pose ⊕ origin ⊕ q``. Children are
posed in their parent's frame and, when the parent stacks children (Stage's default), start on top of
the parent (parent size.z added to z).

The arithmetic follows Stage's operation by operation (the same sums in the same order), because the
raster floors these coordinates to cells and a last-bit difference can move a wall by a cell.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stage_sim.worldfile.bitmap import trace_outlines
from stage_sim.worldfile.description import Model, Pose, WorldDescription

#: Thickness of the walls ``boundary 1`` adds along the edges of the model's size box (Stage's epsilon).
BOUNDARY_THICKNESS = 0.01
#: Stage's stand-in for a zero extent, so that a flat body does not divide by zero.
_TINY = float(np.finfo(np.float64).eps)


@dataclass(frozen=True)
class BodyPolygon:
    """One scaled block: vertices (M, 2) and its z band (model frame, without the model's z).

    ``group`` says which polygons make one shape together: the outlines traced from one image share a
    group (an enclosed outline is a hole in the one around it), every block and boundary wall is its own.
    """

    points: np.ndarray
    z: tuple[float, float]
    group: int = 0


def body_shape(model: Model) -> list[BodyPolygon]:
    """The model's body in its body frame (``origin`` not applied), scaled to its size like Stage."""
    bitmap = model.bitmap
    if bitmap is not None and bitmap.grid is not None:
        polygons = _map_polygons(model)
    elif bitmap is not None:
        traced = trace_outlines(bitmap.occupied)
        polygons = _calc_size([BodyPolygon(p, (0.0, 1.0)) for p in traced], model.size)
    else:
        blocks = [BodyPolygon(b.points, b.z, group) for group, b in enumerate(model.blocks)]
        polygons = _calc_size(blocks, model.size)
    if model.boundary:
        polygons = _calc_size(polygons, model.size) + _boundary_walls(polygons, model.size)
    # Stage sizes the body once more at the end of loading the model.
    return _calc_size(polygons, model.size) if bitmap is None or bitmap.grid is None else polygons


def body_polygons(model: Model) -> list[BodyPolygon]:
    """The model's body in its pose frame: :func:`body_shape` with the model's ``origin`` applied."""
    origin = model.origin
    frame = Pose(origin.x, origin.y, 0.0, origin.yaw)
    return [
        BodyPolygon(transform_points(p.points, frame), (p.z[0] + origin.z, p.z[1] + origin.z), p.group)
        for p in body_shape(model)
    ]


def body_frame(model: Model, pose: Pose) -> Pose:
    """Global frame of the body's points for a model at global ``pose``: ``pose ⊕ origin`` (z not included)."""
    origin = model.origin
    return pose.compose(Pose(origin.x, origin.y, 0.0, origin.yaw))


def global_poses(description: WorldDescription) -> dict[int, Pose]:
    """Global pose of every model, keyed by ``id(model)`` (models are plain mutable dataclasses)."""
    return tree_poses(description.models)


def tree_poses(models: list[Model]) -> dict[int, Pose]:
    """:func:`global_poses` of the top-level ``models`` and their subtrees only (models added to a world)."""
    poses: dict[int, Pose] = {}

    def visit(model: Model, parent: Pose | None, parent_model: Model | None) -> None:
        if parent is None:
            pose = model.pose
        else:
            lift = parent_model.size[2] if parent_model is not None and parent_model.stack_children else 0.0
            pose = parent.compose(Pose(model.pose.x, model.pose.y, model.pose.z + lift, model.pose.yaw))
        poses[id(model)] = pose
        for child in model.children:
            visit(child, pose, model)

    for top in models:
        visit(top, None, None)
    return poses


def transform_points(points: np.ndarray, pose: Pose) -> np.ndarray:
    """Points (M, 2) given in a frame at ``pose`` → world coordinates, summed in Stage's order."""
    c, s = np.cos(pose.yaw), np.sin(pose.yaw)
    x, y = points[:, 0], points[:, 1]
    out = np.empty((len(points), 2))
    out[:, 0], out[:, 1] = pose.x + x * c - y * s, pose.y + x * s + y * c
    return out


def _calc_size(polygons: list[BodyPolygon], size: tuple[float, float, float]) -> list[BodyPolygon]:
    """Stage's ``CalcSize``: stretch the joint bounding box to ``size`` and centre it (z: scale only). The box,
    offset and scales are a handful of numbers, worked out in Python floats (the same IEEE arithmetic as numpy's,
    without an array call each: a world of many small models, or an episode's boxes, makes this twice per model)."""
    if not polygons:
        return []
    points = polygons[0].points if len(polygons) == 1 else np.concatenate([p.points for p in polygons])
    (low_x, low_y), (high_x, high_y) = points.min(axis=0).tolist(), points.max(axis=0).tolist()
    z_low, z_high = min(p.z[0] for p in polygons), max(p.z[1] for p in polygons)
    extent = [e if abs(e) >= _TINY else _TINY for e in (high_x - low_x, high_y - low_y, z_high - z_low)]
    offset = np.array([low_x + extent[0] / 2.0, low_y + extent[1] / 2.0])
    scale = np.array([size[0] / extent[0], size[1] / extent[1]], dtype=np.float64)
    scale_z = float(size[2]) / extent[2]
    return [BodyPolygon((p.points - offset) * scale, (p.z[0] * scale_z, p.z[1] * scale_z), p.group)
            for p in polygons]


def _boundary_walls(polygons: list[BodyPolygon], size: tuple[float, float, float]) -> list[BodyPolygon]:
    """The four thin rectangles ``boundary 1`` adds inside the body's bounding box (Stage's order)."""
    if polygons:
        points = np.concatenate([p.points for p in polygons])
        (x0, y0), (x1, y1) = points.min(axis=0), points.max(axis=0)
        z0, z1 = min(p.z[0] for p in polygons), max(p.z[1] for p in polygons)
    else:
        (x0, y0), (x1, y1), (z0, z1) = (-size[0] / 2, -size[1] / 2), (size[0] / 2, size[1] / 2), (0.0, size[2])
    w, h, t = x1 - x0, y1 - y0, BOUNDARY_THICKNESS
    rects = ((x0, y0, t, h), (x0, y0, w, t), (x0, y1 - t, w, t), (x1 - t, y0, t, h))
    first = max((p.group for p in polygons), default=-1) + 1
    return [
        BodyPolygon(np.array([[x, y], [x + dx, y], [x + dx, y + dy], [x, y + dy]]), (0.0, z1 - z0), first + k)
        for k, (x, y, dx, dy) in enumerate(rects)
    ]


def _map_polygons(model: Model) -> list[BodyPolygon]:
    """A map_server map's outlines at its own resolution and origin: no trimming, no stretching (§9.2)."""
    grid = model.bitmap.grid
    rows = model.bitmap.occupied.shape[0]
    ox, oy, oyaw = grid.origin
    corner = Pose(ox, oy, 0.0, oyaw)
    return [
        BodyPolygon(transform_points(np.stack([p[:, 0], p[:, 1] + rows], axis=1) * grid.resolution, corner),
                    (0.0, model.size[2]))
        for p in trace_outlines(model.bitmap.occupied)
    ]
