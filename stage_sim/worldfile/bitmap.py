"""Reading images for Stage ``bitmap`` bodies (and, through :func:`read_image`, map_server maps).

Stage (FLTK) tests only the first byte of each pixel: grey, or red for colour images. A pixel is
occupied iff that byte is <= 127. Alpha is ignored. The occupied pixels' bounding box is later stretched
to the model ``size`` (spec §9.1), hence :func:`occupied_bounding_box`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np
from PIL import Image, UnidentifiedImageError

from stage_sim.worldfile.errors import SourceLocation, WorldError

#: Largest first-channel value that Stage still counts as occupied.
STAGE_OCCUPIED_MAX = 127

_DIRECT_MODES = {"L": 1, "RGB": 3, "RGBA": 4}
_SIXTEEN_BIT_MODES = {"I", "I;16", "I;16B", "I;16L", "I;16N"}


@dataclass(frozen=True)
class ImagePixels:
    """8-bit pixels of an image, shape (H, W, C) with C = 1 (grey), 3 (RGB) or 4 (RGBA); row 0 = top.

    Grey+alpha is expanded to RGBA (what SDL_image and GraphicsMagick hand to map_server), palette images
    to the RGB(A) colours a viewer shows, 16-bit images to their high byte (libpng's ``strip_16``).
    """

    channels: np.ndarray

    @property
    def has_alpha(self) -> bool:
        """True when the last channel is alpha (RGBA)."""
        return self.channels.shape[2] == 4

    @property
    def first(self) -> np.ndarray:
        """The first channel (grey or red), the only one Stage looks at."""
        return self.channels[:, :, 0]


class PixelBox(NamedTuple):
    """Half-open pixel box: ``mask[row0:row1, col0:col1]``; rows counted from the top of the image."""

    row0: int
    row1: int
    col0: int
    col1: int

    @property
    def height(self) -> int:
        """Number of rows in the box."""
        return self.row1 - self.row0

    @property
    def width(self) -> int:
        """Number of columns in the box."""
        return self.col1 - self.col0


def read_image(
    path: Path, requested_at: SourceLocation | None = None, *, kind: str = "bitmap"
) -> ImagePixels:
    """Decode ``path`` into 8-bit channels, turning every failure into a WorldError naming the file.

    ``kind`` names the file in messages ("bitmap", "map image"); ``requested_at`` is where the world or
    YAML file asked for it.
    """
    path = Path(path)
    if not path.is_file():
        what = f"{kind} not found: {path}" if not path.exists() else f"{kind} is not a file: {path}"
        raise WorldError(what, requested_at)
    try:
        with Image.open(path) as image:
            image.load()
            return ImagePixels(_to_channels(image))
    except (OSError, UnidentifiedImageError, SyntaxError, ValueError, Image.DecompressionBombError) as exc:
        raise WorldError(f"cannot read {kind} {path}: {exc}", requested_at) from exc


def _to_channels(image: Image.Image) -> np.ndarray:
    """Convert any Pillow mode to (H, W, C) uint8 as described on :class:`ImagePixels`."""
    mode = image.mode
    if mode in _SIXTEEN_BIT_MODES:
        wide = np.asarray(image, dtype=np.int64)
        return np.clip(wide >> 8, 0, 255).astype(np.uint8)[:, :, np.newaxis]
    if mode == "1":
        image = image.convert("L")
    elif mode == "LA":
        grey, alpha = image.split()
        image = Image.merge("RGBA", (grey, grey, grey, alpha))
    elif mode in ("P", "PA"):
        has_alpha = mode == "PA" or "transparency" in image.info or image.palette.mode == "RGBA"
        image = image.convert("RGBA" if has_alpha else "RGB")
    elif mode not in _DIRECT_MODES:
        image = image.convert("RGB")
    pixels = np.asarray(image, dtype=np.uint8)
    if pixels.ndim == 2:
        pixels = pixels[:, :, np.newaxis]
    return np.ascontiguousarray(pixels)


def stage_occupancy(pixels: ImagePixels) -> np.ndarray:
    """Stage's rule on decoded pixels: occupied iff the first channel is <= 127."""
    return pixels.first <= STAGE_OCCUPIED_MAX


def load_stage_bitmap(path: Path, requested_at: SourceLocation | None = None) -> np.ndarray:
    """Occupied mask of a Stage bitmap: bool (H, W), row 0 = top image row, True = occupied.

    Raises WorldError "bitmap not found: <path>" at ``requested_at`` when the file is missing, and a
    WorldError naming the path when it cannot be decoded.
    """
    return stage_occupancy(read_image(path, requested_at, kind="bitmap"))


def occupied_bounding_box(mask: np.ndarray) -> PixelBox | None:
    """Tightest box around the True pixels of ``mask`` (None when there are none).

    Stage stretches this box, not the whole image, to the model size, so white margins change the scale.
    """
    rows = np.flatnonzero(mask.any(axis=1))
    if rows.size == 0:
        return None
    cols = np.flatnonzero(mask.any(axis=0))
    return PixelBox(int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1)
