"""map_server YAML maps → :class:`OccupancyGrid`, with ROS 1 map_server semantics (spec §9.2).

Per pixel: the mean of the channels (trinary: alpha included; scale/raw: alpha excluded), optionally
negated, gives p = (255 - mean) / 255; p > occupied_thresh → 100, p < free_thresh → 0, else unknown (or
the scaled 1..99 in scale mode). Image row j becomes grid row H-1-j. Palette images are read as the colours
they show (nav2's choice; ROS 1 SDL read palette indices), and only a real alpha channel counts as alpha
(ROS 1 took the last byte of any multi-channel pixel, so RGB scale maps turned blue-free pixels unknown).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from stage_sim.worldfile.bitmap import ImagePixels, read_image
from stage_sim.worldfile.errors import SourceLocation, WorldError
from stage_sim.worldfile.occupancy import FREE, OCCUPIED, UNKNOWN, OccupancyGrid

MODES = ("trinary", "scale", "raw")
REQUIRED_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh")

DEFAULT_OCCUPIED_THRESH = 0.65
DEFAULT_FREE_THRESH = 0.196


def load_map_yaml(path: Path, requested_at: SourceLocation | None = None) -> OccupancyGrid:
    """Load a map_server YAML file and its image (relative to the YAML's directory).

    Every problem raises WorldError: a missing YAML at ``requested_at``; syntax errors, missing keys, bad
    values and image problems at the line and column of the YAML file where they are.
    """
    path = Path(path)
    if not path.is_file():
        raise WorldError(f"map file not found: {path}", requested_at)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise WorldError(f"cannot read map file {path}: {exc}", requested_at) from exc
    entries = _parse_mapping(text, path)

    def location(key: str | None = None) -> SourceLocation:
        return entries[key][1] if key in entries else SourceLocation(str(path), 1, 1)

    missing = [key for key in REQUIRED_KEYS if key not in entries]
    if missing:
        raise WorldError(f"map file {path} lacks required key(s) {', '.join(missing)}", location())

    image = entries["image"][0]
    if not isinstance(image, str) or not image.strip():
        raise WorldError("bad 'image' value", location("image"), found=repr(image), expected="a file name")
    origin_value = entries["origin"][0]
    if not isinstance(origin_value, list) or len(origin_value) != 3:
        raise WorldError(
            "bad 'origin' value", location("origin"), found=repr(origin_value), expected="[x, y, yaw]"
        )
    origin = tuple(_number(v, "origin", location("origin")) for v in origin_value)
    resolution = _number(entries["resolution"][0], "resolution", location("resolution"))
    negate = _flag(entries["negate"][0], location("negate"))
    occupied_thresh = _number(entries["occupied_thresh"][0], "occupied_thresh", location("occupied_thresh"))
    free_thresh = _number(entries["free_thresh"][0], "free_thresh", location("free_thresh"))
    mode = entries["mode"][0] if "mode" in entries else "trinary"

    image_path = Path(image.strip())
    if not image_path.is_absolute():
        image_path = path.parent / image_path
    return load_map_image(
        image_path,
        resolution,
        origin,  # type: ignore[arg-type]
        negate=negate,
        occupied_thresh=occupied_thresh,
        free_thresh=free_thresh,
        mode=mode,
        requested_at=location("image"),
        parameter_locations={
            k: location(k) for k in ("resolution", "occupied_thresh", "free_thresh", "mode")
        },
    )


def load_map_image(
    image_path: Path,
    resolution: float,
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
    negate: bool = False,
    occupied_thresh: float = DEFAULT_OCCUPIED_THRESH,
    free_thresh: float = DEFAULT_FREE_THRESH,
    mode: str = "trinary",
    *,
    requested_at: SourceLocation | None = None,
    parameter_locations: dict[str, SourceLocation] | None = None,
) -> OccupancyGrid:
    """Convert an image with explicit parameters (the deprecated ``map_server image.pgm 0.05`` form).

    ``parameter_locations`` lets :func:`load_map_yaml` point parameter errors at their YAML lines; without
    it they are reported at ``requested_at``.
    """
    where = parameter_locations or {}
    if not (math.isfinite(resolution) and resolution > 0):
        raise WorldError(
            "bad map resolution",
            where.get("resolution", requested_at),
            found=repr(resolution),
            expected="a positive number of metres per pixel",
        )
    if mode not in MODES:
        raise WorldError(
            "bad map mode", where.get("mode", requested_at), found=repr(mode), expected=" or ".join(MODES)
        )
    for name, value in (("free_thresh", free_thresh), ("occupied_thresh", occupied_thresh)):
        if not 0.0 <= value <= 1.0:
            raise WorldError(
                f"bad {name}", where.get(name, requested_at), found=repr(value), expected="a number in [0, 1]"
            )
    if free_thresh >= occupied_thresh:
        raise WorldError(
            "free_thresh must be below occupied_thresh",
            where.get("free_thresh", requested_at),
            found=f"{free_thresh} >= {occupied_thresh}",
            expected="free_thresh < occupied_thresh",
        )
    pixels = read_image(Path(image_path), requested_at, kind="map image")
    values = map_values(
        pixels, negate=negate, occupied_thresh=occupied_thresh, free_thresh=free_thresh, mode=mode
    )
    return OccupancyGrid(
        values=np.flipud(values).copy(),
        resolution=float(resolution),
        origin=(float(origin[0]), float(origin[1]), float(origin[2])),
        mode=mode,
    )


def map_values(
    pixels: ImagePixels, *, negate: bool, occupied_thresh: float, free_thresh: float, mode: str
) -> np.ndarray:
    """int8 cell values in image row order (row 0 = top), exactly as map_server computes them."""
    channels = pixels.channels
    if mode != "trinary" and pixels.has_alpha:
        channels = channels[:, :, :-1]
    # Same float64 operations as map_server's C++ so threshold ties fall the same way.
    mean = channels.sum(axis=2, dtype=np.float64) / channels.shape[2]
    if negate:
        mean = 255.0 - mean
    if mode == "raw":
        return np.floor(mean).astype(np.uint8).view(np.int8)
    p = (255.0 - mean) / 255.0
    occupied = p > occupied_thresh
    free = p < free_thresh
    values = np.full(p.shape, UNKNOWN, dtype=np.int8)
    values[occupied] = OCCUPIED
    values[free] = FREE
    if mode == "scale":
        between = ~occupied & ~free
        if pixels.has_alpha:
            between &= pixels.channels[:, :, -1] != 0
        ratio = (p[between] - free_thresh) / (occupied_thresh - free_thresh)
        values[between] = np.trunc(1.0 + 98.0 * ratio).astype(np.int8)
    return values


def _parse_mapping(text: str, path: Path) -> dict[str, tuple[Any, SourceLocation]]:
    """Top-level YAML mapping as {key: (value, location of the value)}; YAML errors carry line/column."""
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        if not isinstance(node, yaml.MappingNode):
            found = "an empty file" if node is None else f"a YAML {node.id}"
            where = SourceLocation(str(path), 1, 1) if node is None else _mark(node.start_mark, path)
            raise WorldError(
                "a map file must be a YAML mapping", where, found=found, expected="key: value lines"
            )
        entries: dict[str, tuple[Any, SourceLocation]] = {}
        for key_node, value_node in node.value:
            key = loader.construct_object(key_node, deep=True)
            entries[str(key)] = (
                loader.construct_object(value_node, deep=True),
                _mark(value_node.start_mark, path),
            )
        return entries
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = _mark(mark, path) if mark is not None else SourceLocation(str(path), 1, 1)
        raise WorldError(f"YAML syntax error: {exc.problem or exc.context}", where) from exc
    except yaml.YAMLError as exc:
        raise WorldError(f"YAML error: {exc}", SourceLocation(str(path), 1, 1)) from exc
    finally:
        loader.dispose()


def _mark(mark: yaml.Mark, path: Path) -> SourceLocation:
    """PyYAML marks are 0-based; SourceLocation is 1-based."""
    return SourceLocation(str(path), mark.line + 1, mark.column + 1)


def _number(value: Any, key: str, where: SourceLocation) -> float:
    """A finite number; numeric strings count too (yaml-cpp reads ``5e-2``, which PyYAML leaves a string)."""
    if isinstance(value, bool):
        raise WorldError(f"bad '{key}' value", where, found=repr(value), expected="a number")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise WorldError(f"bad '{key}' value", where, found=repr(value), expected="a number") from None
    if not math.isfinite(number):
        raise WorldError(f"bad '{key}' value", where, found=repr(value), expected="a finite number")
    return number


def _flag(value: Any, where: SourceLocation) -> bool:
    """``negate`` as map_server reads it: 0 or 1 (YAML booleans accepted)."""
    if isinstance(value, bool) or value in (0, 1):
        return bool(value)
    raise WorldError("bad 'negate' value", where, found=repr(value), expected="0 or 1")
