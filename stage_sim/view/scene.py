"""What a page is told once per connection: the world's extent, its static map and every robot's look.

The static map is one PNG with a pixel per raster cell, coloured like the model that occupies it, so the
page scales it (nearest neighbour) without the server drawing anything per frame. Robot bodies and lasers
are sent in the robot frame; frames then carry only poses and ranges.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from stage_sim.maps.body_geometry import body_polygons, global_poses, transform_points

if TYPE_CHECKING:
    from stage_sim.sim.simulation import Simulation

FREE_RGB = (244, 244, 244)
#: Most pixels of the map the page gets (one per cell up to this; a larger world's map is downsampled).
MAP_PIXELS = 16_000_000
"""Free space, as the rendered pictures show it."""


def robot_names(sim: Simulation) -> list[str]:
    """Unique names for the page: the models' names when they are unique and given, else ``robot_<i>``."""
    names = [robot.name for robot in sim.robots]
    if all(names) and len(set(names)) == len(names):
        return names
    return [f"robot_{robot.index}" for robot in sim.robots]


@dataclass(frozen=True)
class Scene:
    """The static part of the view: JSON-ready description and the map as PNG bytes."""

    description: dict[str, Any]
    map_png: bytes
    bounds: tuple[float, float, float, float]

    @classmethod
    def of(cls, sim: Simulation, names: list[str], readonly: bool) -> Scene:
        """The scene of ``sim``; robots are called ``names`` (in robot order) on the page and in its messages."""
        static = sim.static
        rows, cols = static.shape
        x0, y0 = static.origin_xy
        bounds = (x0, y0, x0 + cols * static.resolution, y0 + rows * static.resolution)
        png, step = _map_png(sim)
        description = {
            "type": "scene",
            "world": sim.description.path.name if sim.description.path else "",
            "bounds": list(bounds),
            "map": {"url": "map.png", "origin": [x0, y0], "resolution": static.resolution * step},
            "interval": sim.interval,
            "readonly": readonly,
            "robots": [_robot(sim, i, name) for i, name in enumerate(names)],
        }
        return cls(description, png, bounds)


def css_color(rgba: tuple[float, float, float, float]) -> str:
    """A world-file colour blended over white by its alpha, as ``#rrggbb``."""
    r, g, b, a = rgba
    a = min(max(a, 0.0), 1.0)
    return "#" + "".join(f"{round(255 * (c * a + (1 - a))):02x}" for c in (r, g, b))


def _robot(sim: Simulation, index: int, name: str) -> dict[str, Any]:
    """A robot's blocks (its own and attached models') in the robot frame, its nose and its lasers."""
    robot = sim.robots[index]
    poses = global_poses(sim.description)
    start = poses[id(robot.model)]
    c, s = math.cos(start.yaw), math.sin(start.yaw)
    to_robot = np.array([[c, -s], [s, c]])
    parts = []
    for model in robot.model.walk():
        for polygon in body_polygons(model):
            points = (transform_points(polygon.points, poses[id(model)]) - (start.x, start.y)) @ to_robot
            parts.append({"points": np.round(points, 4).tolist(), "color": css_color(model.color)})
    rangers = [
        {
            "offset": list(r.ray_offset), "yaw": r.ray_yaw, "samples": r.sensor.samples,
            "angle_min": float(r.beam_angles[0]),
            "increment": float(r.beam_angles[1] - r.beam_angles[0]) if r.sensor.samples > 1 else 0.0,
            "range_max": r.sensor.range_max, "color": css_color((*r.sensor.color[:3], 1.0)),
        }
        for r in robot.rangers
    ]
    return {
        "name": name, "color": css_color(robot.model.color), "parts": parts,
        "nose": robot.model.size[0] / 2, "radius": robot.radius, "rangers": rangers,
    }


def _map_png(sim: Simulation) -> tuple[bytes, int]:
    """The static world as a PNG, row 0 at the top (largest y), in its models' colours, and the cells a pixel
    spans: one pixel per raster cell, or fewer for a world too large for that
    (:meth:`~stage_sim.maps.raster.StaticRaster.map_labels`)."""
    from PIL import Image

    static = sim.static
    colors = {model.name: model.color for model in reversed(list(sim.description.walk()))}
    labels, step = static.map_labels(MAP_PIXELS)
    hexas = [css_color(colors.get(body.name, (0.0, 0.0, 0.0, 1.0))) for body in static.bodies]
    palette = np.array([FREE_RGB, *([int(h[i:i + 2], 16) for i in (1, 3, 5)] for h in hexas)], dtype=np.uint8)
    image = Image.fromarray(palette[labels[::-1]])
    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    return buffer.getvalue(), step
