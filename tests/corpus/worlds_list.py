"""The worlds the corpus tests run: Stage's and stage_ros's own (``../shared/corpus`` beside the
repository, or ``STAGE_SIM_CORPUS``) and the small port-style worlds in ``tests/corpus/worlds``.

What each is expected to do is written here once, with the reason, and mirrored in
docs/compatibility.md.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
CORPUS = Path(os.environ.get("STAGE_SIM_CORPUS") or REPO.parent / "shared" / "corpus")
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
    """Every ``.world`` of the corpus (when present) and of tests/corpus/worlds, sorted."""
    found = [World(f"own/{p.relative_to(OWN_WORLDS)}", p) for p in sorted(OWN_WORLDS.rglob("*.world"))]
    if CORPUS.is_dir():
        found += [World(str(p.relative_to(CORPUS)), p) for p in sorted(CORPUS.rglob("*.world"))]
    return found


def params(loading_only: bool = False) -> list:
    """pytest params of the worlds; ``loading_only`` drops the worlds that are expected to fail to load."""
    return [pytest.param(world, id=world.id) for world in worlds() if not (loading_only and world.id in FAILS_TO_LOAD)]


def require_corpus() -> None:
    """Fail in CI, skip with the reason elsewhere, when the corpus is not beside the repository."""
    if CORPUS.is_dir():
        return
    message = f"Stage world corpus not found at {CORPUS} (clone shared/ beside the repository or set STAGE_SIM_CORPUS)"
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)
