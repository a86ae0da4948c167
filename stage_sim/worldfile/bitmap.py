"""Reading images for Stage ``bitmap`` bodies (and, through :func:`read_image`, map_server maps).

Stage (FLTK) tests only the first byte of each pixel: grey, or red for colour images. A pixel is
occupied iff that byte is <= 127. Alpha is ignored. The occupied pixels' bounding box is later stretched
to the model ``size`` (spec §9.1), hence :func:`occupied_bounding_box`.

Stage does not keep the pixels: it traces the borders of the occupied regions into closed polygons
(:func:`trace_outlines`, Stage's ``polys_from_image_file``) and only those polygons' edges ever reach the
world raster, so the exact vertices Stage makes (where it merges straight runs, where it does not) decide
which cells a rotated or scaled bitmap occupies.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from stage_sim.worldfile.errors import SourceLocation, WorldError

if TYPE_CHECKING:
    from PIL import Image

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
    from PIL import Image, UnidentifiedImageError  # only reading images needs Pillow, tracing does not

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
    from PIL import Image

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


def trace_outlines(mask: np.ndarray) -> list[np.ndarray]:
    """Stage's polygons for an occupied mask (row 0 = top): a list of (M, 2) float vertex arrays.

    Vertices are pixel corners with the image y flipped: pixel (col i, row j) spans x in [i, i+1] and
    y in [-(j+1), -j]. As in Stage, every occupied pixel contributes its four directed border edges,
    edges shared by two occupied pixels cancel, and the remaining edges are chained starting from the
    smallest corner (x, then y) still unused; at a corner with two ways on, the smaller end corner is
    taken. A new vertex replaces the previous one when it continues in the same direction, but only once
    the polygon has three vertices, so the first corners of a polygon are never merged (Stage's rule).
    """
    height = mask.shape[0]
    starts, ends = _border_edges(np.asarray(mask, dtype=bool))
    # A corner (x, y) as one integer that sorts like Stage's (x, then y) comparison.
    stride = height + 1
    start_key = starts[:, 0] * stride + starts[:, 1]
    order = np.lexsort((ends[:, 1], ends[:, 0], start_key))
    start_key, ends = start_key[order].tolist(), (ends[order, 0] * stride + ends[order, 1]).tolist()
    first_out: dict[int, int] = {}
    for index in range(len(start_key) - 1, -1, -1):
        first_out[start_key[index]] = index
    used = [False] * len(start_key)
    polygons = []
    for seed in range(len(start_key)):
        if used[seed]:
            continue
        polygons.append(_chain(seed, start_key, ends, first_out, used, stride))
    return polygons


def _border_edges(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Directed edges (start corners, end corners) between occupied pixels and free ones or the outside."""
    padded = np.pad(mask, 1)
    rows, cols = np.nonzero(mask)
    x, y = cols, rows
    sides = (  # (free neighbour, start corner, end corner) in Stage's order: top, right, bottom, left
        (~padded[rows, cols + 1], (x, y), (x + 1, y)),
        (~padded[rows + 1, cols + 2], (x + 1, y), (x + 1, y + 1)),
        (~padded[rows + 2, cols + 1], (x + 1, y + 1), (x, y + 1)),
        (~padded[rows + 1, cols], (x, y + 1), (x, y)),
    )
    starts = np.concatenate([np.stack(start, axis=1)[keep] for keep, start, _ in sides])
    ends = np.concatenate([np.stack(end, axis=1)[keep] for keep, _, end in sides])
    return starts.astype(np.int64), ends.astype(np.int64)


def _chain(
    seed: int, start_key: list[int], ends: list[int], first_out: dict[int, int], used: list[bool], stride: int
) -> np.ndarray:
    """Follow unused edges from edge ``seed`` until none leaves the current corner; merge straight runs."""
    points: list[tuple[int, int]] = []
    edge = seed
    while edge is not None:
        used[edge] = True
        x, y = divmod(start_key[edge], stride)
        point = (x, -y)
        if len(points) > 2:
            (x0, y0), (x1, y1) = points[-2], points[-1]
            straight = _sign(x1 - x0) == _sign(point[0] - x1) and _sign(y1 - y0) == _sign(point[1] - y1)
            if straight:
                points[-1] = point
            else:
                points.append(point)
        else:
            points.append(point)
        edge = _next_unused(ends[edge], start_key, first_out, used)
    return np.array(points, dtype=np.float64)


def _next_unused(corner: int, start_key: list[int], first_out: dict[int, int], used: list[bool]) -> int | None:
    """The first unused edge leaving ``corner`` in Stage's order, None when there is none."""
    index = first_out.get(corner)
    while index is not None and index < len(start_key) and start_key[index] == corner:
        if not used[index]:
            first_out[corner] = index
            return index
        index += 1
    return None


def _sign(value: int) -> int:
    return (value > 0) - (value < 0)
