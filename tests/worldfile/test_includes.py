"""Where includes and bitmaps are found: Stage's rule (beside the top-level world file) first, then beside
the including file, then the current directory; a missing one names every place tried."""

from __future__ import annotations

from pathlib import Path

import pytest
from PIL import Image

from stage_sim.worldfile import bitmap_files, syntax
from stage_sim.worldfile.bundled import bundled_worlds
from stage_sim.worldfile.errors import SourceLocation, WorldError
from stage_sim.worldfile.loader import load_world
from stage_sim.worldfile.search_path import candidate_paths
from stage_sim.worldfile.syntax import parse_world

BASE = "define base position ( size [0.3 0.3 0.2] drive \"omni\" )\n"


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def port_layout(root: Path) -> Path:
    """world/w.world -> include/robots.inc -> include/base.inc, as the ROS 2 Stage ports write it."""
    write(root / "world" / "include" / "base.inc", BASE)
    write(root / "world" / "include" / "robots.inc", 'include "include/base.inc"\ndefine bot base ( )\n')
    return write(root / "world" / "w.world", 'include "include/robots.inc"\nbot( name "r" )\n')


def test_nested_include_two_levels_deep_resolves_beside_the_world_file(tmp_path: Path) -> None:
    world = load_world(port_layout(tmp_path))
    robot = world.robots()[0]
    assert robot.name == "r" and robot.position is not None and robot.position.drive == "omni"
    assert robot.size == (0.3, 0.3, 0.2)


def test_stage_rule_wins_over_the_including_files_folder(tmp_path: Path) -> None:
    write(tmp_path / "world" / "parts.inc", "define part position ( drive \"omni\" )\n")
    write(tmp_path / "world" / "include" / "parts.inc", "define part position ( drive \"car\" )\n")
    write(tmp_path / "world" / "include" / "robots.inc", 'include "parts.inc"\n')
    syntax = parse_world(write(tmp_path / "world" / "w.world", 'include "include/robots.inc"\npart( )\n'))
    assert syntax.files[2] == tmp_path / "world" / "parts.inc"
    assert load_world(tmp_path / "world" / "w.world").robots()[0].position.drive == "omni"


def test_include_relative_to_the_including_file_is_found_next(tmp_path: Path) -> None:
    write(tmp_path / "robots" / "parts" / "laser.inc", "define laser_part ranger ( sensor( samples 3 ) )\n")
    write(tmp_path / "robots" / "parts" / "body.inc", 'include "laser.inc"\ndefine body position ( laser_part( ) )\n')
    write(tmp_path / "robots" / "robot.inc", 'include "parts/body.inc"\n')
    world = write(tmp_path / "worlds" / "w.world", 'include "../robots/robot.inc"\nbody( )\n')
    robot = load_world(world).robots()[0]
    assert robot.children[0].sensors[0].samples == 3


def test_include_from_the_current_directory_comes_last(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    write(tmp_path / "shared" / "common.inc", BASE)
    world = write(tmp_path / "worlds" / "w.world", 'include "common.inc"\nbase( )\n')
    monkeypatch.chdir(tmp_path / "shared")
    assert load_world(world).robots()[0].size == (0.3, 0.3, 0.2)


def test_world_loaded_from_another_working_directory(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    world = port_layout(tmp_path / "project")
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    assert load_world(world).robots()[0].name == "r"
    assert load_world(Path("..") / "project" / "world" / "w.world").robots()[0].name == "r"


def test_absolute_include_paths_at_both_levels(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    base = write(tmp_path / "lib" / "base.inc", BASE)
    robots = write(tmp_path / "lib" / "sub" / "robots.inc", f'include "{base}"\ndefine bot base ( )\n')
    world = write(tmp_path / "worlds" / "w.world", f'include "{robots}"\nbot( )\n')
    monkeypatch.chdir(tmp_path / "lib" / "sub")
    assert parse_world(world).files == [world, robots, base]
    assert load_world(world).robots()[0].size == (0.3, 0.3, 0.2)


def test_missing_nested_include_names_every_place_tried(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    robots = write(tmp_path / "world" / "include" / "robots.inc", 'a 1\n  include "include/base.inc"\n')
    world = write(tmp_path / "world" / "w.world", 'include "include/robots.inc"\n')
    (tmp_path / "cwd").mkdir()
    monkeypatch.chdir(tmp_path / "cwd")
    monkeypatch.delenv("STAGEPATH", raising=False)
    with pytest.raises(WorldError) as info:
        load_world(world)
    assert info.value.location == SourceLocation(str(robots), 2, 3)
    tried = [tmp_path / "world" / "include" / "base.inc", tmp_path / "world" / "include" / "include" / "base.inc",
             tmp_path / "cwd" / "include" / "base.inc"]
    assert f"tried {', '.join(map(str, tried))} (found No such file or directory" in str(info.value)
    assert str(info.value).startswith(f'{robots}:2:3: cannot open include file "include/base.inc"')


def test_bitmap_named_in_an_include_is_found_beside_the_world_then_beside_the_include(tmp_path: Path) -> None:
    for folder, name, size in (("bitmaps", "wide.png", (4, 2)), ("include", "tall.png", (2, 4))):
        (tmp_path / "world" / folder).mkdir(parents=True)
        Image.new("L", size, 0).save(tmp_path / "world" / folder / name)
    write(tmp_path / "world" / "include" / "maps.inc",
          'define wide model ( bitmap "bitmaps/wide.png" )\ndefine tall model ( bitmap "tall.png" )\n')
    world = write(tmp_path / "world" / "w.world", 'include "include/maps.inc"\nwide( )\ntall( )\n')
    wide, tall = load_world(world).models
    assert wide.bitmap.path == tmp_path / "world" / "bitmaps" / "wide.png" and wide.bitmap.occupied.shape == (2, 4)
    assert tall.bitmap.path == tmp_path / "world" / "include" / "tall.png" and tall.bitmap.occupied.shape == (4, 2)


def test_missing_bitmap_names_every_place_tried(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    world = write(tmp_path / "world" / "w.world", 'model(\n  bitmap "maps/none.png"\n)\n')
    with pytest.raises(WorldError) as info:
        load_world(world)
    assert info.value.location == SourceLocation(str(world), 2, 3)
    assert f"tried {tmp_path / 'world' / 'maps' / 'none.png'}, {tmp_path / 'maps' / 'none.png'}" in str(info.value)


@pytest.mark.parametrize("world", bundled_worlds())
def test_bundled_worlds_load_by_stages_rule_alone(world: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The bundled worlds load in the real Stage too: every include and bitmap is found beside the world file."""
    def stage_place_only(name: str, world_file: Path, written_in: Path) -> list[Path]:
        return candidate_paths(name, world_file, written_in)[:1]

    monkeypatch.setattr(syntax, "candidate_paths", stage_place_only)
    monkeypatch.setattr(bitmap_files, "candidate_paths", stage_place_only)
    assert load_world(world).models
