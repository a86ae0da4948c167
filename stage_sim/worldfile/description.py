"""Typed description of a Stage world: what a world file means, in SI units, with no syntax left.

Lengths are metres, angles radians, times seconds. Built by :mod:`stage_sim.worldfile.loader`; read by the
simulation, the ``inspect`` command and the ROS layer.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from stage_sim.worldfile.errors import SourceLocation
from stage_sim.worldfile.occupancy import OccupancyGrid


@dataclass(frozen=True)
class Pose:
    """A pose in a parent frame: x, y, z in metres and yaw in radians (counter-clockwise)."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    yaw: float = 0.0

    def compose(self, other: Pose) -> Pose:
        """Return ``self ⊕ other``: ``other`` expressed in the frame that ``self`` is expressed in."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return Pose(
            self.x + c * other.x - s * other.y,
            self.y + s * other.x + c * other.y,
            self.z + other.z,
            self.yaw + other.yaw,
        )


@dataclass(frozen=True)
class WorldWarning:
    """Something the loader accepted but a user should know about (Stage 3 leftovers, unknown keys)."""

    message: str
    location: SourceLocation | None = None

    def __str__(self) -> str:
        return f"{self.location}: {self.message}" if self.location is not None else self.message


@dataclass(frozen=True)
class WindowSettings:
    """The GUI ``window`` entity; used for rendering scale and centre only."""

    size: tuple[float, float] = (400.0, 300.0)
    center: tuple[float, float] = (0.0, 0.0)
    rotate: tuple[float, float] = (0.0, 0.0)
    scale: float = 1.0
    show_data: bool = False
    show_trails: bool = False
    show_grid: bool = True


@dataclass(frozen=True)
class WorldSettings:
    """World-level (entity 0) properties."""

    name: str = ""
    resolution: float = 0.02
    interval_sim: float = 0.1
    quit_time: float = 0.0
    speedup: float = 1.0
    threads: int = 1
    unit_length: float = 1.0
    unit_angle: float = math.pi / 180.0
    window: WindowSettings | None = None


@dataclass(frozen=True)
class Block:
    """One polygon of a model body, in block coordinates (before scaling the model to its size)."""

    points: np.ndarray
    z: tuple[float, float] = (0.0, 1.0)
    location: SourceLocation | None = None


@dataclass(frozen=True)
class Bitmap:
    """A body traced from an image (Stage ``bitmap``) or a map_server YAML map.

    For a Stage image ``occupied`` holds the image's occupied pixels (row 0 = top row of the image) and
    ``grid`` is None; for a ``.yaml`` map ``grid`` holds the map_server grid and ``occupied`` its
    occupied mask in the same image row order.
    """

    path: Path
    occupied: np.ndarray
    grid: OccupancyGrid | None = None
    location: SourceLocation | None = None


@dataclass(frozen=True)
class Sensor:
    """One transducer of a ranger (a ``sensor( )`` block)."""

    pose: Pose = Pose()
    size: tuple[float, float, float] = (0.02, 0.02, 0.02)
    range_min: float = 0.0
    range_max: float = 5.0
    fov: float = 0.1
    samples: int = 1
    noise: tuple[float, float, float] = (0.0, 0.0, 0.0)
    color: tuple[float, float, float, float] = (0.0, 0.0, 1.0, 0.15)


@dataclass(frozen=True)
class PositionSettings:
    """Keys that only position models have.

    ``velocity_bounds`` and ``acceleration_bounds`` are (xmin, xmax, ymin, ymax, zmin, zmax, amin, amax)
    in m/s (m/s²) and rad/s (rad/s²). ``odom_error`` is None when the world file does not give it (the
    simulation then draws one from its seeded generator).
    """

    drive: str = "diff"
    velocity_bounds: tuple[float, ...] = (-1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -math.pi / 2, math.pi / 2)
    acceleration_bounds: tuple[float, ...] = (-1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -math.pi / 2, math.pi / 2)
    localization: str = "gps"
    localization_origin: Pose | None = None
    odom_error: tuple[float, float, float, float] | None = None
    wheelbase: float = 1.0


@dataclass
class Model:
    """One model of the world tree, with every property resolved (defines applied, units converted)."""

    type: str
    name: str
    location: SourceLocation | None = None
    pose: Pose = Pose()
    size: tuple[float, float, float] = (0.4, 0.4, 1.0)
    origin: Pose = Pose()
    color: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 1.0)
    blocks: list[Block] = field(default_factory=list)
    bitmap: Bitmap | None = None
    boundary: bool = False
    obstacle_return: bool = True
    ranger_return: float = 1.0
    update_interval: float = 0.1
    stack_children: bool = True
    gui_nose: bool = False
    gui_outline: bool = False
    gui_grid: bool = False
    gui_move: bool = True
    position: PositionSettings | None = None
    sensors: list[Sensor] = field(default_factory=list)
    children: list[Model] = field(default_factory=list)

    def walk(self) -> Iterator[Model]:
        """This model and all its descendants in pre-order (Stage's DFS order)."""
        yield self
        for child in self.children:
            yield from child.walk()


@dataclass
class WorldDescription:
    """Everything a world file says: settings, the model tree and the warnings raised while reading it."""

    path: Path
    settings: WorldSettings
    models: list[Model]
    warnings: list[WorldWarning] = field(default_factory=list)

    def walk(self) -> Iterator[Model]:
        """Every model of the world in pre-order DFS (world-file order)."""
        for model in self.models:
            yield from model.walk()

    def robots(self) -> list[Model]:
        """The position models, indexed as stageros indexes robots (pre-order DFS)."""
        return [m for m in self.walk() if m.type == "position"]
