"""Typed, unit-converting access to one entity's properties, and the tables of keys each entity knows.

Stage reads every value through typed readers (float, int, length, angle, string, n-tuple) that take the
first N values, ignore extras and exit when there are fewer; lengths scale by ``unit_length`` and angles
by ``unit_angle``. :class:`Properties` does the same, but raises :class:`WorldError` pointing at the value
instead of exiting, and remembers which keys were read so the loader can report the rest.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field

from stage_sim.worldfile.colors import RGBA, x11_color
from stage_sim.worldfile.description import Pose, WorldWarning
from stage_sim.worldfile.errors import SourceLocation, WorldError
from stage_sim.worldfile.lexer import integer_value, is_clean_number, number_value
from stage_sim.worldfile.syntax import Property, Value

LENGTH_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}
ANGLE_UNITS = {"degrees": math.pi / 180.0, "radians": 1.0}

WORLD_IGNORED = frozenset({"show_clock", "show_clock_interval", "paused", "confirm_on_quit"})
WINDOW_IGNORED = frozenset(
    {
        "show_clock",
        "show_clock_interval",
        "show_footprints",
        "show_occupancy",
        "show_blocks",
        "show_flags",
        "show_status",
        "show_tree",
        "show_trailarrows",
        "show_trailrise",
        "show_trailfast",
        "show_screenshots",
        "show_perspective",
        "show_boundary",
        "show_follow",
        "pcam_on",
        "pcam_loc",
        "pcam_angle",
        "interval",
        "screenshots",
        "follow_model",
        "ortho",
        "perspective",
        "lock",
    }
)
MODEL_IGNORED = frozenset(
    {
        "fiducial_return",
        "fiducial_key",
        "blob_return",
        "gripper_return",
        "mass",
        "watts",
        "watts_give",
        "watts_take",
        "joules",
        "joules_capacity",
        "kjoules",
        "charging_bump",
        "friction",
        "map_resolution",
        "trail_length",
        "trail_interval",
        "say",
        "alwayson",
        "noblocks",
        "debug",
        "gui_grid_interval",
    }
)
"""Model keys Stage reads that change nothing this simulator computes: accepted without a warning."""

STAGE3_KEYS = {
    "range_max": "Stage 4 ignores it outside the old 'laser' model; the ranger keeps its range [0 5] m",
    "range_min": "Stage 4 ignores it; the range comes only from 'range [min max]' inside sensor( )",
    "laser_return": "Stage 4 ignores it (use ranger_return)",
    "view": "Stage 4 ignores it",
    "resolution": "Stage 4 ignores it inside rangers (every ray is cast)",
    "interval_real": "Stage 4 ignores it",
    "gui_movemask": "Stage 4 ignores it (use gui_move)",
}
"""Stage 3 keys that Stage 4 silently ignores, with what that means, for the warning."""

MODEL_ALIASES = {"size3": "size", "origin3": "origin"}


@dataclass
class Warnings:
    """Collects warnings once each: a define used by many instances reports its problems only once."""

    items: list[WorldWarning] = field(default_factory=list)
    _seen: set[tuple[str, SourceLocation | None]] = field(default_factory=set)

    def add(self, message: str, location: SourceLocation | None) -> None:
        if (message, location) not in self._seen:
            self._seen.add((message, location))
            self.items.append(WorldWarning(message, location))


@dataclass(frozen=True)
class Units:
    """Metres per file length unit and radians per file angle unit (``unit_length`` / ``unit_angle``)."""

    length: float = 1.0
    angle: float = math.pi / 180.0


class Properties:
    """The merged properties of one entity (later ones override earlier ones) with typed readers."""

    def __init__(
        self,
        properties: Iterable[Property],
        units: Units,
        warnings: Warnings,
        aliases: dict[str, str] | None = None,
    ) -> None:
        self.units = units
        self.warnings = warnings
        self._props: dict[str, Property] = {}
        for prop in properties:
            if aliases and prop.name in aliases:
                new = aliases[prop.name]
                warnings.add(f"Stage 3 key '{prop.name}' read as '{new}' (Stage 4 ignores it)", prop.location)
                prop = Property(new, prop.values, prop.location, prop.is_tuple)
            self._props.pop(prop.name, None)  # keep file order of the winning occurrence
            self._props[prop.name] = prop
        self._used: set[str] = set()

    def __contains__(self, key: str) -> bool:
        return key in self._props

    def unread(self) -> list[Property]:
        """Properties no reader asked for, in file order (for unknown-key and leftover warnings)."""
        return [p for name, p in self._props.items() if name not in self._used]

    def take(self, key: str) -> Property | None:
        """The property (marked as read), or None when absent."""
        self._used.add(key)
        return self._props.get(key)

    def _values(self, key: str, count: int) -> Property | None:
        prop = self.take(key)
        if prop is not None and len(prop.values) < count:
            noun = "value" if count == 1 else "values"
            raise WorldError(
                f"'{key}' has too few values",
                prop.location,
                found=f"{len(prop.values)} values",
                expected=f"{count} {noun}",
            )
        return prop

    def _number(self, key: str, value: Value) -> float:
        if value.is_string:
            raise WorldError(
                f"'{key}' needs a number", value.location, found=f'string "{value.text}"', expected="a number"
            )
        result = number_value(value.text)
        if not math.isfinite(result):
            raise WorldError(f"'{key}' is out of range", value.location, found=value.text, expected="a finite number")
        if not is_clean_number(value.text):
            self.warnings.add(
                f"number '{value.text}' read as {result:g} (Stage reads the longest valid prefix)", value.location
            )
        return result

    def numbers(self, key: str, count: int, scales: Iterable[float] | None = None) -> tuple[float, ...] | None:
        """The first ``count`` values times ``scales`` (default 1 each); None when absent."""
        prop = self._values(key, count)
        if prop is None:
            return None
        factors = list(scales) if scales is not None else [1.0] * count
        return tuple(self._number(key, v) * f for v, f in zip(prop.values[:count], factors, strict=True))

    def number(self, key: str, default: float, scale: float = 1.0) -> float:
        found = self.numbers(key, 1, [scale])
        return default if found is None else found[0]

    def length(self, key: str, default: float) -> float:
        """A length in metres (``default`` is already in metres)."""
        return self.number(key, default, self.units.length)

    def angle(self, key: str, default: float) -> float:
        """An angle in radians (``default`` is already in radians)."""
        return self.number(key, default, self.units.angle)

    def lengths(self, key: str, count: int) -> tuple[float, ...] | None:
        return self.numbers(key, count, [self.units.length] * count)

    def integer(self, key: str, default: int) -> int:
        """C ``atoi`` semantics: ``1.000`` → 1."""
        prop = self._values(key, 1)
        if prop is None:
            return default
        self._number(key, prop.values[0])
        return integer_value(prop.values[0].text)

    def flag(self, key: str, default: bool) -> bool:
        return bool(self.integer(key, int(default)))

    def string(self, key: str, default: str) -> str:
        """A string; a number is read as its text, as Stage does."""
        prop = self._values(key, 1)
        return default if prop is None else prop.values[0].text

    def choice(self, key: str, default: str, allowed: Iterable[str]) -> str:
        """A string that must be one of ``allowed``."""
        value = self.string(key, default)
        options = list(allowed)
        if value not in options:
            prop = self._props[key]
            raise WorldError(
                f"unknown {key}",
                prop.values[0].location,
                found=f'"{value}"',
                expected=" or ".join(f'"{o}"' for o in options),
            )
        return value

    def pose(self, key: str, default: Pose | None = None) -> Pose | None:
        """``[x y z a]`` with unit conversion; a Stage 3 ``[x y a]`` is read as ``[x y 0 a]``."""
        prop = self.take(key)
        if prop is None:
            return default
        if len(prop.values) == 3:
            self.warnings.add(
                f"Stage 3 pose '{key} [x y a]' read as [x y 0 a] (Stage 4 refuses fewer than 4 values)", prop.location
            )
            x, y, a = (self._number(key, v) for v in prop.values)
            return Pose(x * self.units.length, y * self.units.length, 0.0, a * self.units.angle)
        length, angle = self.units.length, self.units.angle
        x, y, z, a = self.numbers(key, 4, [length, length, length, angle]) or (0.0, 0.0, 0.0, 0.0)
        return Pose(x, y, z, a)

    def size(self, default_height: float) -> tuple[float, float, float] | None:
        """``size [x y z]`` in metres; a Stage 3 ``[x y]`` gets ``default_height`` (Stage 4 refuses it)."""
        prop = self.take("size")
        if prop is not None and len(prop.values) == 2:
            self.warnings.add(
                f"Stage 3 size [x y] read as [x y {default_height:g}] (Stage 4 refuses fewer than 3 values)",
                prop.location,
            )
            x, y = self.lengths("size", 2) or (0.0, 0.0)
            return (x, y, default_height)
        found = self.lengths("size", 3)
        return None if found is None else (found[0], found[1], found[2])

    def color(self, default: RGBA) -> RGBA:
        """``color "X11 name"``, overridden by ``color_rgba [r g b a]`` as in Stage; unknown names warn."""
        result = default
        prop = self._values("color", 1)
        if prop is not None:
            name = prop.values[0].text
            found = x11_color(name)
            if found is None:
                self.warnings.add(
                    f'unknown colour "{name}" (not in this X11 table); default kept', prop.values[0].location
                )
            else:
                result = found
        rgba = self.numbers("color_rgba", 4)
        if rgba is not None:
            result = (rgba[0], rgba[1], rgba[2], rgba[3])
        return result

    def location(self, key: str) -> SourceLocation:
        return self._props[key].location

    def require(self, ok: bool, key: str, found: object, expected: str) -> None:
        """Raise a WorldError at ``key`` unless ``ok`` (for values Stage would accept but cannot work)."""
        if not ok:
            raise WorldError(f"bad value for '{key}'", self.location(key), found=str(found), expected=expected)

    def report_unread(self, kind: str, ignored: frozenset[str] = frozenset()) -> None:
        """Warn about every unread key: Stage 3 leftovers say how Stage 4 reads them, others are unknown."""
        for prop in self.unread():
            if prop.name in ignored:
                continue
            if prop.name in STAGE3_KEYS:
                self.warnings.add(f"Stage 3 key '{prop.name}' ignored: {STAGE3_KEYS[prop.name]}", prop.location)
            else:
                self.warnings.add(f"unknown key '{prop.name}' in {kind} ignored", prop.location)
