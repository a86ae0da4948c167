"""The file a model's ``bitmap`` names: found like an include, read once per load.

Stage opens a relative bitmap beside the top-level world file (``Model::Load`` joins it to the world
file's folder, wherever the ``bitmap`` key was written); the same fallbacks as for includes follow
(:mod:`stage_sim.worldfile.search_path`). A ``.yaml`` file is a map_server map, anything else a Stage
image.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stage_sim.worldfile.description import Bitmap
from stage_sim.worldfile.errors import WorldError
from stage_sim.worldfile.search_path import SEARCH_ORDER, candidate_paths, describe_tried
from stage_sim.worldfile.syntax import Property

YAML_SUFFIXES = (".yaml", ".yml")


class BitmapFiles:
    """The bitmaps of one world load, each file read once however many models use it."""

    def __init__(self, world_file: Path) -> None:
        self.world_file = world_file
        self._loaded: dict[Path, Bitmap] = {}

    def load(self, prop: Property, name: str) -> Bitmap:
        """The bitmap ``name`` given by ``prop``; a WorldError at ``prop`` naming every place tried."""
        candidates = candidate_paths(name, self.world_file, Path(prop.location.file))
        path = next((c for c in candidates if c in self._loaded or c.is_file()), None)
        if path is None:
            raise WorldError(
                f'bitmap file not found: "{name}"; tried {describe_tried(candidates)}',
                prop.location,
                found="no such file",
                expected=f"an image or .yaml map; {SEARCH_ORDER}",
            )
        if path not in self._loaded:
            self._loaded[path] = self._read(path, prop)
        return self._loaded[path]

    @staticmethod
    def _read(path: Path, prop: Property) -> Bitmap:
        if path.suffix.lower() in YAML_SUFFIXES:
            from stage_sim.worldfile.map_yaml import load_map_yaml

            grid = load_map_yaml(path, requested_at=prop.location)
            return Bitmap(path, np.ascontiguousarray(grid.occupied[::-1]), grid, prop.location)
        from stage_sim.worldfile.bitmap import load_stage_bitmap

        return Bitmap(path, load_stage_bitmap(path, requested_at=prop.location), None, prop.location)
