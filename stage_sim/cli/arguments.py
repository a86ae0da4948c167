"""What the subcommands share: argument types with clear errors."""

from __future__ import annotations

import argparse
import math
from pathlib import Path


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
