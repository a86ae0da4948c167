"""The worlds the corpus tests run: Stage's and stage_ros's own (``tests/data/corpus``, copied from the
project's shared corpus with their origin and licence in its README) and the small port-style worlds in
``tests/corpus/worlds``.

What each is expected to do is written here once, with the reason, and mirrored in
docs/compatibility.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
CORPUS = REPO / "tests" / "data" / "corpus"
OWN_WORLDS = Path(__file__).resolve().parent / "worlds"

FAILS_TO_LOAD = {
    "stage-worlds/wifi.world": "unknown entity type 'map'",
    "stage-worlds/wifi/commando.world": 'cannot open include file "pioneer.inc"',
    "stage-worlds/wifi/hosp_wifi.world": 'cannot open include file "pioneer.inc"',
    "stage-worlds/wifi/hosp_wifi_5.world": 'cannot open include file "pioneer.inc"',
    "stage-worlds/wifi/wifi.world": 'bitmap file not found: "bitmaps/cave.png"',
    "stage-worlds/wifi/wifi_simple.world": 'bitmap file not found: "bitmaps/cave.png"',
    "stage-worlds/wifi/wifi_ray.world": 'bitmap file not found: "bitmaps/cave_f.png"',
}
"""Stage 3 worlds that Stage 4 cannot load either: the message each must stop with (exit status 2)."""


@dataclass(frozen=True)
class World:
    id: str
    """Path relative to the corpus (``stage-worlds/...``) or ``own/...`` for this repository's worlds."""
    path: Path


def worlds() -> list[World]:
    """Every ``.world`` of tests/corpus/worlds and of the corpus, sorted."""
    found = [World(f"own/{p.relative_to(OWN_WORLDS)}", p) for p in sorted(OWN_WORLDS.rglob("*.world"))]
    return found + [World(str(p.relative_to(CORPUS)), p) for p in sorted(CORPUS.rglob("*.world"))]


def params(loading_only: bool = False) -> list:
    """pytest params of the worlds; ``loading_only`` drops the worlds that are expected to fail to load."""
    return [pytest.param(world, id=world.id) for world in worlds() if not (loading_only and world.id in FAILS_TO_LOAD)]

