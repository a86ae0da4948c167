"""What the subcommands share: finding a world by path or bundled name, and argument types with clear errors."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from stage_sim.worldfile.errors import WorldError


def resolve_world(name: str) -> Path:
    """An existing file as given, else a bundled world by name (when bundled data is installed)."""
    path = Path(name)
    if path.is_file():
        return path
    try:
        from stage_sim.worldfile.bundled import find_world
    except ImportError:
        return path
    try:
        return find_world(name)
    except FileNotFoundError as exc:
        raise WorldError(str(exc)) from exc


def image_path(text: str) -> Path:
    path = Path(text)
    if path.suffix.lower() not in (".png", ".gif"):
        raise argparse.ArgumentTypeError(f"'{text}' must end in .png or .gif")
    return path


def positive(text: str) -> float:
    value = float(text)
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be a positive number, not {text}")
    return value


def count(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be 0 or more, not {text}")
    return value
