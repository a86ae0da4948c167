"""Colours and line weights of the rendered frames, in one place so tests and pictures agree.

Stage's window draws on white with models in their own colours; we keep that, with a light grey floor so
that white or pale models stay visible, and translucent laser lines like Stage's "show data".
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

RGB = tuple[int, int, int]

FREE: RGB = (244, 244, 244)
"""Free space (and everything outside the static world's raster)."""

GRID: RGB = (214, 214, 214)
"""Grid lines, drawn on free space only."""

CAPTION_BACKGROUND: RGB = (255, 255, 255)
CAPTION_TEXT: RGB = (0, 0, 0)
CAPTION_LINE = 16
"""Pixels per text line of the strip under the map that holds the sim clock and the scale bar."""

CAPTION_ONE_LINE_MIN_WIDTH = 240
"""Narrower frames put the scale bar on a second caption line, under the clock."""

NOSE: RGB = (0, 0, 0)

LASER_ALPHA = 0.3
"""Opacity of one laser ray. Stage fills its fans at the sensor's alpha (0.15 by default); a single thin
line needs more to be seen, and overlapping rays near the sensor still add up to the sensor colour."""

TRAIL_LIGHTEN = 0.5
"""A trail is its robot's colour mixed this much with white: visible, yet distinct from the body."""

OUTLINE_DARKEN = 0.6
"""Block outlines are the fill colour times this factor (Stage draws outlines darker than the fill)."""


def blend(rgba: tuple[float, float, float, float], under: RGB = FREE) -> RGB:
    """An RGBA colour with float channels in 0..1 (as world files give them) painted over ``under``."""
    r, g, b, a = rgba
    return _rgb(255 * c * a + u * (1.0 - a) for c, u in zip((r, g, b), under, strict=True))


def darker(rgb: RGB, factor: float = OUTLINE_DARKEN) -> RGB:
    """``rgb`` scaled towards black."""
    return _rgb(c * factor for c in rgb)


def trail_color(rgb: RGB) -> RGB:
    """The colour of a robot's trail: its body colour lightened towards white."""
    return _rgb(c + (255 - c) * TRAIL_LIGHTEN for c in rgb)


def laser_ink(rgba: tuple[float, float, float, float]) -> tuple[int, int, int, int]:
    """Pillow RGBA ink for one ray of a sensor of colour ``rgba`` (its own alpha is replaced, see above)."""
    r, g, b, _ = rgba
    return (round(255 * r), round(255 * g), round(255 * b), round(255 * LASER_ALPHA))


def _rgb(channels: Iterable[float]) -> RGB:
    r, g, b = (round(c) for c in channels)
    return (r, g, b)


def table(colors: list[RGB]) -> np.ndarray:
    """Colour lookup table (K, 3) uint8 for label images: label 0 is free space."""
    return np.array([FREE, *colors], dtype=np.uint8).reshape(-1, 3)
