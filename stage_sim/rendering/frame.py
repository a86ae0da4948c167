"""One frame of a simulation: static world, trails, laser rays, robot bodies, sim clock and scale bar.

A frame covers the static world's raster at ``scale`` px/m (default: the world's ``window scale``) with a
caption strip under it, so every frame of a run has the same size whatever the robots do. World +y is up.
The static layer (with the optional grid) and the caption's scale bar never change, so they are drawn once
per scale and each frame copies them before drawing the moving parts with Pillow.

Frames are drawn from a :class:`Snapshot`, not from the live simulation, so that a recorder can keep cheap
snapshots while the simulation runs and draw them afterwards.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from PIL import Image, ImageDraw

from stage_sim.maps.body_geometry import body_polygons, global_poses, transform_points
from stage_sim.rendering import palette
from stage_sim.rendering.caption import caption_strip, draw_clock
from stage_sim.sim.simulation import Simulation

DEFAULT_LONG_SIDE_PX = 800
"""Longer side of the map when the world has no ``window`` to take a scale from."""

MAX_PIXELS = 40_000_000
"""Larger frames are refused: a typo in a scale would otherwise exhaust memory."""

GRID_MIN_PX = 10
"""Grid lines are 1 m apart (Stage's grid) unless that is closer than this; then 2, 5, 10 m..."""


@dataclass(frozen=True)
class Snapshot:
    """The moving state a frame shows: sim time (s), true poses (N, 3), scan ranges ``[robot][ranger]``."""

    sim_time: float
    poses: np.ndarray
    ranges: tuple[tuple[np.ndarray, ...], ...]

    @classmethod
    def of(cls, sim: Simulation) -> Snapshot:
        """A copy of the simulation's current state, safe to keep while the simulation runs on."""
        ranges = tuple(tuple(scan.ranges.copy() for scan in scans) for scans in sim.scans)
        return cls(sim.sim_time, sim.true_poses.copy(), ranges)


@dataclass(frozen=True)
class View:
    """Where world points land: ``scale`` px/m, the map's lower-left corner at world ``origin``."""

    scale: float
    origin: tuple[float, float]
    width: int
    map_height: int
    caption_height: int

    @property
    def height(self) -> int:
        """Frame height: the map and the caption strip under it."""
        return self.map_height + self.caption_height

    def continuous(self, points: np.ndarray) -> np.ndarray:
        """World points (M, 2) → (column, row) pixel coordinates; pixel k spans [k, k + 1), as Pillow draws."""
        cols = (points[:, 0] - self.origin[0]) * self.scale
        rows = self.map_height - (points[:, 1] - self.origin[1]) * self.scale
        return np.stack([cols, rows], axis=1)

    def pixel(self, x: float, y: float) -> tuple[int, int]:
        """(row, column) of the pixel containing world point (x, y), to index a rendered array."""
        col, row = self.continuous(np.array([[x, y]], dtype=float))[0]
        return math.floor(row), math.floor(col)


@dataclass(frozen=True)
class _Part:
    """One body block of a robot in the robot frame, drawn in its own model's colour as Stage does."""

    points: np.ndarray
    fill: palette.RGB
    outline: palette.RGB


@dataclass(frozen=True)
class _Ranger:
    """A laser as drawn: ray origin in the robot frame and beam directions relative to the heading."""

    offset: tuple[float, float]
    angles: np.ndarray
    ink: tuple[int, int, int, int]


@dataclass(frozen=True)
class _Robot:
    parts: tuple[_Part, ...]
    rangers: tuple[_Ranger, ...]
    nose: float
    trail: palette.RGB


class FrameRenderer:
    """Draws frames of one simulation. Holds no reference to it, so it can be cached per simulation."""

    def __init__(self, sim: Simulation) -> None:
        self._static = sim.static
        window = sim.description.settings.window
        self._window_scale = window.scale if window is not None else None
        self._labels, self._colors = _static_labels(sim)
        self._robots = _robot_drawings(sim)
        self._layers: dict[tuple[float, bool], tuple[Image.Image, Image.Image]] = {}

    def view(self, scale: float | None = None) -> View:
        """The frame geometry at ``scale`` px/m (None: the world's ``window scale``)."""
        rows, cols = self._static.shape
        extent = (cols * self._static.resolution, rows * self._static.resolution)
        if scale is None:
            scale = self._window_scale or DEFAULT_LONG_SIDE_PX / max(extent)
        if not (scale > 0 and math.isfinite(scale)):
            raise ValueError(f"scale must be a positive number of pixels per metre, not {scale}")
        width, map_height = (max(1, math.ceil(round(e * scale, 6))) for e in extent)
        lines = 1 if width >= palette.CAPTION_ONE_LINE_MIN_WIDTH else 2
        view = View(float(scale), self._static.origin_xy, width, map_height, lines * palette.CAPTION_LINE)
        if view.width * view.height > MAX_PIXELS:
            raise ValueError(f"a {width}x{map_height} px frame is too large at {scale:g} px/m; lower the scale")
        return view

    def image(
        self,
        snapshot: Snapshot,
        scale: float | None = None,
        lasers: bool = True,
        trails: Sequence[np.ndarray] | None = None,
        grid: bool = False,
    ) -> Image.Image:
        """The frame of ``snapshot`` as an RGB Pillow image (see :meth:`Simulation.render` for the options)."""
        view = self.view(scale)
        background, caption = self._cached_layers(view, grid)
        frame = background.copy()
        draw = ImageDraw.Draw(frame, "RGBA")
        if trails is not None:
            self._draw_trails(draw, view, trails)
        if lasers:
            self._draw_lasers(draw, view, snapshot)
        self._draw_robots(draw, view, snapshot.poses)
        frame.paste(caption, (0, view.map_height))  # covers whatever spilled below the map
        draw_clock(draw, view.map_height, snapshot.sim_time)
        return frame

    def _cached_layers(self, view: View, grid: bool) -> tuple[Image.Image, Image.Image]:
        key = (view.scale, grid)
        if key not in self._layers:
            caption = caption_strip(view.width, view.caption_height, view.scale)
            background = Image.new("RGB", (view.width, view.height))
            background.paste(Image.fromarray(self._map_rgb(view, grid)), (0, 0))
            background.paste(caption, (0, view.map_height))
            self._layers[key] = (background, caption)
        return self._layers[key]

    def _map_rgb(self, view: View, grid: bool) -> np.ndarray:
        """The static world at the view's scale, (map_height, width, 3) uint8."""
        labels = self._labels
        rows, cols = labels.shape
        cell = self._static.resolution * view.scale  # pixels per cell
        # Each pixel shows the cell under its centre (the padding row/column is free space)...
        px_cols = np.minimum(((np.arange(view.width) + 0.5) / cell).astype(np.int64), cols)
        px_rows = np.minimum(((view.map_height - np.arange(view.map_height) - 0.5) / cell).astype(np.int64), rows)
        shown = np.pad(labels, ((0, 1), (0, 1)))[np.ix_(px_rows, px_cols)]
        # ...and each occupied cell marks the pixel under its own centre, so walls thinner than a pixel stay.
        r, c = np.nonzero(labels)
        shown[view.map_height - 1 - ((r + 0.5) * cell).astype(np.int64), ((c + 0.5) * cell).astype(np.int64)] = (
            labels[r, c]
        )
        rgb = palette.table(self._colors)[shown]
        if grid:
            rgb[_grid_mask(view) & (shown == 0)] = palette.GRID
        return rgb

    def _draw_trails(self, draw: ImageDraw.ImageDraw, view: View, trails: Sequence[np.ndarray]) -> None:
        width = _line_width(view.scale, 0.03)
        for robot, trail in zip(self._robots, trails, strict=True):
            points = np.asarray(trail, dtype=float)
            if points.size == 0:
                continue
            for piece in np.split(points[:, :2], np.flatnonzero(~np.isfinite(points[:, :2]).all(axis=1))):
                piece = piece[np.isfinite(piece).all(axis=1)]
                if len(piece) >= 2:
                    draw.line(_flat(view.continuous(piece)), fill=robot.trail, width=width, joint="curve")

    def _draw_lasers(self, draw: ImageDraw.ImageDraw, view: View, snapshot: Snapshot) -> None:
        for robot, pose, ranges in zip(self._robots, snapshot.poses, snapshot.ranges, strict=True):
            for ranger, distances in zip(robot.rangers, ranges, strict=True):
                origin = _place(np.array([ranger.offset]), pose)
                angles = pose[2] + ranger.angles
                ends = origin + distances[:, None] * np.stack([np.cos(angles), np.sin(angles)], axis=1)
                start = tuple(view.continuous(origin)[0].tolist())
                for end in view.continuous(ends).tolist():
                    draw.line((*start, *end), fill=ranger.ink)

    def _draw_robots(self, draw: ImageDraw.ImageDraw, view: View, poses: np.ndarray) -> None:
        width = _line_width(view.scale, 0.02)
        for robot, pose in zip(self._robots, poses, strict=True):
            for part in robot.parts:
                draw.polygon(_flat(view.continuous(_place(part.points, pose))), fill=part.fill, outline=part.outline)
            nose = _place(np.array([[0.0, 0.0], [robot.nose, 0.0]]), pose)
            draw.line(_flat(view.continuous(nose)), fill=palette.NOSE, width=width)


_RENDERERS: weakref.WeakKeyDictionary[Simulation, FrameRenderer] = weakref.WeakKeyDictionary()


def renderer_for(sim: Simulation) -> FrameRenderer:
    """The renderer of ``sim``: built on first use, kept (with its static layers) while the simulation lives."""
    renderer = _RENDERERS.get(sim)
    if renderer is None:
        renderer = _RENDERERS[sim] = FrameRenderer(sim)
    return renderer


def render(
    sim: Simulation,
    scale: float | None = None,
    lasers: bool = True,
    trails: Sequence[np.ndarray] | None = None,
    grid: bool = False,
) -> np.ndarray:
    """The world now, as Stage's window shows it: an (H, W, 3) uint8 RGB image with +y up.

    Static world, robot bodies with a heading nose, laser rays to their hits (``lasers``), per robot an
    (M, 2) array of past positions as a trail (``trails``, NaN rows break a line), a grid, the sim clock
    and a scale bar. ``scale`` is pixels per metre (default: the world's ``window scale``); the frame
    covers the static world, so every frame of a run has the same size.
    """
    return np.array(renderer_for(sim).image(Snapshot.of(sim), scale, lasers, trails, grid))


def _static_labels(sim: Simulation) -> tuple[np.ndarray, list[palette.RGB]]:
    """Per cell 0 (free) or k (the k-th static body, drawn in its model's colour; later bodies on top)."""
    color_of: dict[str, tuple[float, float, float, float]] = {}
    for model in sim.description.walk():
        color_of.setdefault(model.name, model.color)
    static = sim.static
    static.grid.check_dense("a picture of the world")
    labels, _ = static.map_labels()
    return labels, [palette.blend(color_of[body.name]) for body in static.bodies]


def _robot_drawings(sim: Simulation) -> list[_Robot]:
    """Every robot's blocks (its own and its attached models') in the robot frame, with its lasers."""
    poses = global_poses(sim.description)
    drawings = []
    for robot in sim.robots:
        start = poses[id(robot.model)]
        c, s = math.cos(start.yaw), math.sin(start.yaw)
        to_robot = np.array([[c, -s], [s, c]])
        parts = []
        for model in robot.model.walk():
            fill = palette.blend(model.color)
            for polygon in body_polygons(model):
                world = transform_points(polygon.points, poses[id(model)])
                parts.append(_Part((world - (start.x, start.y)) @ to_robot, fill, palette.darker(fill)))
        rangers = tuple(
            _Ranger(r.ray_offset, r.ray_yaw + r.beam_angles, palette.laser_ink(r.sensor.color)) for r in robot.rangers
        )
        trail = palette.trail_color(palette.blend(robot.model.color))
        drawings.append(_Robot(tuple(parts), rangers, robot.model.size[0] / 2, trail))
    return drawings


def _place(points: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Robot-frame points (M, 2) → world, for a pose row (x, y, yaw)."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return points @ np.array([[c, s], [-s, c]]) + pose[:2]


def _flat(pixels: np.ndarray) -> list[float]:
    return pixels.ravel().tolist()


def _line_width(scale: float, metres: float) -> int:
    return max(1, round(scale * metres))


def _grid_mask(view: View) -> np.ndarray:
    """Pixels on grid lines, at world multiples of a spacing of at least :data:`GRID_MIN_PX` pixels."""
    wanted = GRID_MIN_PX / view.scale
    unit = 10.0 ** math.floor(math.log10(wanted))
    spacing = max(1.0, next(m * unit for m in (1, 2, 5, 10) if m * unit >= wanted))
    mask = np.zeros((view.map_height, view.width), dtype=bool)
    x0, y0 = view.origin
    xs = np.arange(math.ceil(x0 / spacing), math.floor((x0 + view.width / view.scale) / spacing) + 1) * spacing
    ys = np.arange(math.ceil(y0 / spacing), math.floor((y0 + view.map_height / view.scale) / spacing) + 1) * spacing
    pixels = view.continuous(np.stack([xs, np.full(len(xs), y0)], axis=1))[:, 0].astype(np.int64)
    mask[:, pixels[(pixels >= 0) & (pixels < view.width)]] = True
    pixels = view.continuous(np.stack([np.full(len(ys), x0), ys], axis=1))[:, 1].astype(np.int64)
    mask[pixels[(pixels >= 0) & (pixels < view.map_height)], :] = True
    return mask
