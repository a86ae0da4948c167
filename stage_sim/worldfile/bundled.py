"""Finding the bundled worlds, maps and robots without needing ROS.

A plain venv has no ament index (``AMENT_PREFIX_PATH`` is unset), so the data is looked for where each
kind of install puts it: the source tree (editable installs, running from a checkout), the
``share/stage_sim`` data_files folder of a pip or colcon install, and only last the ament index.
"""

from __future__ import annotations

import contextlib
import site
import sys
from pathlib import Path

from stage_sim.worldfile.errors import WorldError

PACKAGE = "stage_sim"
WORLD_SUFFIX = ".world"


def _candidates() -> list[Path]:
    """Directories that may hold ``worlds/``, ``maps/`` and ``robots/``, most specific first."""
    source_tree = Path(__file__).resolve().parents[2]
    places = [source_tree, Path(sys.prefix) / "share" / PACKAGE, Path(site.getuserbase()) / "share" / PACKAGE]
    try:
        from ament_index_python.packages import get_package_share_directory
    except ImportError:
        return places
    # Not in the index, or AMENT_PREFIX_PATH unset (OSError): just not an ament install.
    with contextlib.suppress(LookupError, OSError, ValueError):
        places.append(Path(get_package_share_directory(PACKAGE)))
    return places


def data_root() -> Path:
    """The directory holding the bundled ``worlds/``, ``maps/`` and ``robots/`` folders.

    Raises FileNotFoundError listing every place looked at when none has a ``worlds/`` folder.
    """
    places = _candidates()
    for place in places:
        if (place / "worlds").is_dir():
            return place
    tried = ", ".join(str(place) for place in places)
    raise FileNotFoundError(f"bundled stage_sim data (a 'worlds' folder) not found; looked in {tried}")


def bundled_worlds() -> list[str]:
    """File names of the bundled worlds, sorted (empty when no bundled data is installed)."""
    try:
        worlds = data_root() / "worlds"
    except FileNotFoundError:
        return []
    return sorted(p.name for p in worlds.iterdir() if p.is_file() and p.suffix == WORLD_SUFFIX)


class WorldNotFoundError(WorldError, FileNotFoundError):
    """Neither a file nor a bundled world: a world error for the CLI (exit 2), a missing file for Python callers."""


def find_world(name_or_path: str | Path) -> Path:
    """Resolve what a user typed: an existing file as given, else a bundled world by name or stem.

    ``rooms.world`` and ``rooms`` both find the bundled rooms world from any working directory. Raises
    :class:`WorldNotFoundError` saying what was tried and naming the bundled worlds when nothing matches.
    """
    given = Path(name_or_path)
    if given.is_file():
        return given
    available = bundled_worlds()
    is_name = given.name == str(name_or_path)
    if is_name:
        for candidate in (given.name, given.name + WORLD_SUFFIX):
            if candidate in available:
                return data_root() / "worlds" / candidate
    listing = ", ".join(available) if available else "none installed"
    tried = "no such file, nor a bundled world of that name" if is_name else "no such file"
    raise WorldNotFoundError(f"world file not found: {name_or_path} ({tried}; bundled worlds: {listing})")
