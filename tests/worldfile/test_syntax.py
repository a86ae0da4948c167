"""Grammar of Stage world files (spec §8.2): properties, entities, defines and includes."""

from __future__ import annotations

from pathlib import Path

import pytest

from stage_sim.worldfile.errors import SourceLocation, WorldError
from stage_sim.worldfile.syntax import Define, Entity, parse_world, parse_world_text


def parse(text: str):
    return parse_world_text(text, "w.world")


def values(prop) -> list[str]:
    return [v.text for v in prop.values]


def test_top_level_properties_belong_to_the_world() -> None:
    syntax = parse('resolution 0.02\nname "x"  # comment\nsize [1 2 3]\n')
    assert [p.name for p in syntax.properties] == ["resolution", "name", "size"]
    assert values(syntax.properties[2]) == ["1", "2", "3"] and syntax.properties[2].is_tuple
    assert syntax.properties[1].values[0].is_string and not syntax.properties[0].values[0].is_string
    assert syntax.properties[2].location == SourceLocation("w.world", 3, 1)
    assert syntax.properties[2].values[1].location == SourceLocation("w.world", 3, 9)


def test_several_properties_on_one_line() -> None:
    syntax = parse('a 1 b [2] c "x"')
    assert [(p.name, values(p)) for p in syntax.properties] == [("a", ["1"]), ("b", ["2"]), ("c", ["x"])]


def test_tuples_may_mix_numbers_and_strings_and_be_empty() -> None:
    syntax = parse('t [1 "a" -2]\ne [ ]')
    assert values(syntax.properties[0]) == ["1", "a", "-2"]
    assert syntax.properties[1].values == () and syntax.properties[1].is_tuple


def test_entity_with_open_paren_on_a_later_line() -> None:
    syntax = parse('model\n\n(\n  pose [1 2 0 0]\n  color "red"\n)\n')
    (entity,) = syntax.items
    assert isinstance(entity, Entity) and entity.type == "model"
    assert entity.location == SourceLocation("w.world", 1, 1)
    assert [p.name for p in entity.properties] == ["pose", "color"]


def test_nested_entities_keep_order() -> None:
    syntax = parse("position( a 1 ranger( sensor( samples 3 ) sensor( samples 4 ) ) model( ) b 2 )")
    (robot,) = syntax.items
    assert [c.type for c in robot.children] == ["ranger", "model"]
    assert [p.name for p in robot.properties] == ["a", "b"]
    assert [values(s.properties[0]) for s in robot.children[0].children] == [["3"], ["4"]]


def test_define_holds_name_parent_and_body() -> None:
    syntax = parse("define pr2 position\n(\n  size [1 1 1]\n  topurg( )\n)\npr2( )")
    define, instance = syntax.items
    assert isinstance(define, Define)
    assert (define.name, define.parent) == ("pr2", "position")
    assert define.location == SourceLocation("w.world", 1, 1)
    assert define.body.type == "position" and define.body.children[0].type == "topurg"
    assert isinstance(instance, Entity) and instance.type == "pr2"


def test_defines_and_entities_stay_in_file_order() -> None:
    syntax = parse("m( )\ndefine a model ( )\na( )\nx 1")
    assert [type(i).__name__ for i in syntax.items] == ["Entity", "Define", "Entity"]
    assert [p.name for p in syntax.properties] == ["x"]


def test_include_splices_relative_to_the_including_file(tmp_path: Path) -> None:
    (tmp_path / "worlds").mkdir()
    (tmp_path / "robots" / "parts").mkdir(parents=True)
    (tmp_path / "robots" / "robot.inc").write_text('include "parts/laser.inc"\ndefine r position ( l( ) )\nq 2\n')
    (tmp_path / "robots" / "parts" / "laser.inc").write_text("define l ranger ( )\n")
    world = tmp_path / "worlds" / "w.world"
    world.write_text('a 1\ninclude "../robots/robot.inc" these tokens ( are ignored\nr( )\n')
    syntax = parse_world(world)
    assert [p.name for p in syntax.properties] == ["a", "q"]
    assert [getattr(i, "name", getattr(i, "type", None)) for i in syntax.items] == ["l", "r", "r"]
    assert syntax.files[1] == tmp_path / "robots" / "robot.inc"
    laser = syntax.items[0]
    assert laser.location.file == str(tmp_path / "robots" / "parts" / "laser.inc")
    assert laser.location.line == 1


def test_include_uses_the_reader_without_disk_io() -> None:
    files = {Path("/virtual/inc/r.inc"): "define r position ( )\n"}

    def reader(path: Path) -> str:
        if path not in files:
            raise FileNotFoundError(2, "No such file or directory")
        return files[path]

    syntax = parse_world_text('include "inc/r.inc"\nr( )', "/virtual/w.world", reader)
    assert isinstance(syntax.items[0], Define)


def test_include_is_found_through_stagepath(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "sick.inc").write_text("define sick ranger ( )\n")
    monkeypatch.setenv("STAGEPATH", str(tmp_path / "lib"))
    syntax = parse_world_text('include "somewhere/sick.inc"\n', tmp_path / "w.world")
    assert syntax.items[0].name == "sick"


def test_missing_include_names_tried_path_and_include_location(tmp_path: Path) -> None:
    world = tmp_path / "w.world"
    world.write_text('a 1\n  include "nope/r.inc"\n')
    with pytest.raises(WorldError) as info:
        parse_world(world)
    assert info.value.location == SourceLocation(str(world), 2, 3)
    assert str(tmp_path / "nope" / "r.inc") in str(info.value)


def test_include_cycle_names_the_chain(tmp_path: Path) -> None:
    (tmp_path / "a.inc").write_text('include "b.inc"\n')
    (tmp_path / "b.inc").write_text('x 1\ninclude "a.inc"\n')
    world = tmp_path / "w.world"
    world.write_text('include "a.inc"\n')
    with pytest.raises(WorldError) as info:
        parse_world(world)
    message = str(info.value)
    assert info.value.location == SourceLocation(str(tmp_path / "b.inc"), 2, 1)
    assert f"{tmp_path / 'a.inc'} -> {tmp_path / 'b.inc'} -> {tmp_path / 'a.inc'}" in message


def test_a_file_including_itself_is_a_cycle(tmp_path: Path) -> None:
    world = tmp_path / "w.world"
    world.write_text('include "w.world"\n')
    with pytest.raises(WorldError, match="include cycle"):
        parse_world(world)


def test_byte_order_mark_is_ignored() -> None:
    assert parse("\ufeffa 1").properties[0].name == "a"


def test_missing_world_file(tmp_path: Path) -> None:
    with pytest.raises(WorldError) as info:
        parse_world(tmp_path / "none.world")
    assert info.value.location == SourceLocation(str(tmp_path / "none.world"), 1, 1)
    assert "cannot read world file" in str(info.value)
