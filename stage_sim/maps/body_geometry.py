"""Where model bodies are: Stage's block scaling and the global poses of the model tree.

All blocks of a model are scaled jointly so that the bounding box of their points becomes the model's
``size`` (x, y) and is centred on the model origin; z values are scaled by size.z / (zmax − zmin) of all
blocks. A body point q then sits at ``pose ⊕ origin ⊕ q``. Children are posed in their parent's frame and,
when the parent stacks children (Stage's default), start on top of the parent (parent size.z added to z).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stage_sim.worldfile.description import Model, Pose, WorldDescription


@dataclass(frozen=True)
class BodyPolygon:
    """One scaled block: vertices (M, 2) in the model's pose frame (origin applied) and its z band."""

    points: np.ndarray
    z: tuple[float, float]


def body_polygons(model: Model) -> list[BodyPolygon]:
    """The model's blocks scaled to its size and shifted by its origin (Stage §8.6)."""
    if not model.blocks:
        return []
    all_points = np.concatenate([b.points for b in model.blocks])
    low, high = all_points.min(axis=0), all_points.max(axis=0)
    extent = np.where(high - low > 0, high - low, 1.0)
    scale = np.array(model.size[:2]) / extent
    centre = (low + high) / 2.0
    z_low = min(b.z[0] for b in model.blocks)
    z_high = max(b.z[1] for b in model.blocks)
    z_scale = model.size[2] / (z_high - z_low) if z_high > z_low else 1.0
    c, s = np.cos(model.origin.yaw), np.sin(model.origin.yaw)
    rotation = np.array([[c, -s], [s, c]])
    offset = np.array([model.origin.x, model.origin.y])
    polygons = []
    for block in model.blocks:
        local = (block.points - centre) * scale
        placed = local @ rotation.T + offset
        z = (block.z[0] * z_scale + model.origin.z, block.z[1] * z_scale + model.origin.z)
        polygons.append(BodyPolygon(points=placed, z=z))
    return polygons


def global_poses(description: WorldDescription) -> dict[int, Pose]:
    """Global pose of every model, keyed by ``id(model)`` (models are plain mutable dataclasses)."""
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

    for top in description.models:
        visit(top, None, None)
    return poses


def transform_points(points: np.ndarray, pose: Pose) -> np.ndarray:
    """Points (M, 2) given in a frame at ``pose`` → world coordinates."""
    c, s = np.cos(pose.yaw), np.sin(pose.yaw)
    return points @ np.array([[c, s], [-s, c]]) + np.array([pose.x, pose.y])
