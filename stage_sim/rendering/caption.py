"""The caption strip under a frame's map: the sim clock (per frame) and a scale bar (fixed per scale).

One line when the frame is wide enough, else two (clock above, scale bar below); either way the height
depends only on the frame width, so every frame of a run has the same size.
"""

from __future__ import annotations

import math
from functools import cache

from PIL import Image, ImageDraw, ImageFont

from stage_sim.rendering import palette


def caption_strip(width: int, height: int, scale: float) -> Image.Image:
    """The strip with a scale bar at the right end of its last line; the clock goes on the first line."""
    caption = Image.new("RGB", (width, height), palette.CAPTION_BACKGROUND)
    draw = ImageDraw.Draw(caption)
    draw.line((0, 0, width, 0), fill=palette.GRID)
    one_line = height == palette.CAPTION_LINE
    length = _nice_at_most(width / (4 if one_line else 2) / scale)
    top = height - palette.CAPTION_LINE
    right, left, middle = width - 5, width - 5 - length * scale, top + palette.CAPTION_LINE // 2
    draw.line((left, middle, right, middle), fill=palette.CAPTION_TEXT)
    for x in (left, right):
        draw.line((x, middle - 3, x, middle + 3), fill=palette.CAPTION_TEXT)
    label = f"{length:g} m"
    _draw_text(draw, (left - 4 - _font().getlength(label), top), label)
    return caption


def draw_clock(draw: ImageDraw.ImageDraw, top: int, seconds: float) -> None:
    """The sim clock (h:mm:ss.cc) at the left of the caption line starting at row ``top``."""
    centis = round(seconds * 100)
    hours, centis = divmod(centis, 360_000)
    minutes, centis = divmod(centis, 6_000)
    _draw_text(draw, (4, top), f"sim {hours}:{minutes:02d}:{centis / 100:05.2f}")


def _nice_at_most(metres: float) -> float:
    """The longest 1, 2 or 5 × 10^k metres that is not longer than ``metres``."""
    unit = 10.0 ** math.floor(math.log10(metres))
    return next(m * unit for m in (5, 2, 1) if m * unit <= metres)


def _draw_text(draw: ImageDraw.ImageDraw, corner: tuple[float, float], text: str) -> None:
    """``text`` at x = corner[0], centred vertically in the caption line whose top is corner[1]."""
    top, bottom = _font().getbbox(text)[1::2]
    y = corner[1] + (palette.CAPTION_LINE - top - bottom) / 2
    draw.text((corner[0], y), text, fill=palette.CAPTION_TEXT, font=_font())


@cache
def _font() -> ImageFont.ImageFont | ImageFont.FreeTypeFont:
    """Pillow's built-in font: no font file to ship or find."""
    return ImageFont.load_default()
