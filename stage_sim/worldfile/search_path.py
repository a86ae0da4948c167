"""Where a file named in a world file (an ``include`` or a ``bitmap``) is looked for, in order.

Stage's ``Worldfile::LoadTokenInclude`` joins a relative name to the directory of the world file being
loaded, the top-level one, even for an include written inside an included file; its ``FileOpen`` then
tries the ``STAGEPATH`` folders. Worlds written for other simulators' rule (relative to the including
file) and worlds run from the folder that holds their includes also exist, so after Stage's place come
the including file's folder and the current directory, then STAGEPATH by base name. The first file that
opens wins; when none does, the error lists every place tried.
"""

from __future__ import annotations

import os
from pathlib import Path

STAGEPATH = "STAGEPATH"
SEARCH_ORDER = ("a relative name is looked for beside the world file as in Stage, then beside the file that "
                "names it, then in the current directory and STAGEPATH")


def candidate_paths(name: str, world_file: Path, written_in: Path) -> list[Path]:
    """The places to try for ``name``, written in ``written_in`` while loading ``world_file``, without repeats."""
    given = Path(name).expanduser()
    if given.is_absolute():
        places = [given]
    else:
        places = [world_file.parent / given, written_in.parent / given, Path.cwd() / given]
    places += [Path(folder) / given.name for folder in os.environ.get(STAGEPATH, "").split(os.pathsep) if folder]
    unique: dict[str, Path] = {}
    for place in places:
        place = Path(os.path.normpath(place))
        unique.setdefault(os.path.normcase(os.path.abspath(place)), place)
    return list(unique.values())


def describe_tried(places: list[Path]) -> str:
    """``a, b, c``: the places tried, for an error message."""
    return ", ".join(str(place) for place in places)
