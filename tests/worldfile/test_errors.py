"""Every kind of broken world raises WorldError at the right file, line and column (and nothing loads)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from stage_sim.worldfile.errors import SourceLocation, WorldError
from stage_sim.worldfile.loader import load_world, load_world_text

WORLD = "/virtual/w.world"
MESSAGE = re.compile(r"^(?P<file>[^:]+):(?P<line>\d+):(?P<column>\d+): .+ \(found .+, expected .+\)$")


def error_of(text: str, files: dict[str, str] | None = None) -> WorldError:
    """Load ``text`` as /virtual/w.world (includes served from ``files``) and return the error it raises."""
    virtual = {Path(name): content for name, content in (files or {}).items()}

    def reader(path: Path) -> str:
        if path not in virtual:
            raise FileNotFoundError(2, "No such file or directory")
        return virtual[path]

    with pytest.raises(WorldError) as info:
        load_world_text(text, WORLD, reader)
    error = info.value
    match = MESSAGE.match(str(error))
    assert match is not None, str(error)
    assert error.location is not None
    assert (match["file"], int(match["line"]), int(match["column"])) == (
        error.location.file, error.location.line, error.location.column,
    )  # fmt: skip
    return error


def at(line: int, column: int, file: str = WORLD) -> SourceLocation:
    return SourceLocation(file, line, column)


# --- lexical -----------------------------------------------------------------------------------------


def test_unexpected_character() -> None:
    error = error_of("model(\n  pose [1 2 0 0] $\n)")
    assert error.location == at(2, 18) and "'$'" in str(error)


def test_number_with_exponent() -> None:
    error = error_of("resolution 2e-2")
    assert error.location == at(1, 12) and "found '2e-2'" in str(error)


def test_unterminated_string() -> None:
    assert error_of('model( name "abc\n)').location == at(1, 13)


# --- syntax ------------------------------------------------------------------------------------------


def test_property_without_value_on_its_line() -> None:
    error = error_of("model(\n  size\n  [1 2 3]\n)")
    assert error.location == at(2, 3) and "'size' has no value" in str(error)


def test_tuple_spanning_lines() -> None:
    error = error_of("model( size [1 2\n 3] )")
    assert error.location == at(1, 13) and "unterminated tuple" in str(error)


def test_comment_inside_a_tuple_ends_it() -> None:
    assert error_of("size [1 2 # three\n 3]").location == at(1, 6)


def test_word_inside_a_tuple() -> None:
    error = error_of("pose [1 two 0 0]")
    assert error.location == at(1, 9) and "found word 'two'" in str(error)


def test_nested_tuple() -> None:
    assert error_of("pose [1 [2] 0 0]").location == at(1, 9)


def test_unterminated_entity_is_reported_at_its_opening() -> None:
    error = error_of("model( size [1 1 1] )\nposition\n(\n  ranger( sensor( ) )\n")
    assert error.location == at(3, 1) and "unterminated entity 'position'" in str(error)


def test_stray_token_at_top_level() -> None:
    error = error_of("model( )\n)")
    assert error.location == at(2, 1) and "found ')'" in str(error)


def test_two_values_for_one_scalar_property() -> None:
    assert error_of('name "a" "b"').location == at(1, 10)


def test_word_after_property_name() -> None:
    assert error_of("model( drive diff )").location == at(1, 14)


def test_include_inside_an_entity() -> None:
    assert error_of('model(\n include "x.inc"\n)').location == at(2, 2)


def test_define_inside_an_entity() -> None:
    assert error_of("model( define a model ( ) )").location == at(1, 8)


def test_malformed_define() -> None:
    assert error_of("define a ( )").location == at(1, 10)
    assert error_of("define a model size 1").location == at(1, 16)


def test_include_without_file_name() -> None:
    assert error_of("include robot.inc").location == at(1, 9)


def test_missing_include_names_the_tried_path() -> None:
    error = error_of('a 1\ninclude "../robots/r.inc"\n')
    assert error.location == at(2, 1)
    assert "/robots/r.inc" in str(error) and "No such file" in str(error)


def test_include_cycle_names_the_chain() -> None:
    error = error_of('include "a.inc"', {"/virtual/a.inc": 'include "w.world"'})
    assert error.location == at(1, 1, "/virtual/a.inc")
    assert "include cycle: /virtual/w.world -> /virtual/a.inc -> /virtual/w.world" in str(error)


def test_error_inside_an_include_points_into_the_include() -> None:
    error = error_of('include "r.inc"\nr( )\n', {"/virtual/r.inc": "define r position (\n  size [1]\n)\n"})
    assert error.location == at(2, 3, "/virtual/r.inc")


def test_entities_nested_too_deeply() -> None:
    error = error_of("model(" * 150 + ")" * 150)
    assert error.location.line == 1 and "nested too deeply" in str(error)


# --- meaning -----------------------------------------------------------------------------------------


def test_unknown_entity_type() -> None:
    error = error_of("model( )\nrobot( pose [0 0 0 0] )")
    assert error.location == at(2, 1) and "unknown entity type 'robot'" in str(error)


def test_unknown_define_parent() -> None:
    error = error_of("define r robot ( )\nr( )")
    assert error.location == at(2, 1) and "unknown entity type 'robot'" in str(error)


def test_define_cycle() -> None:
    error = error_of("define a b ( )\ndefine b a ( )\nmodel( a( ) )")
    assert error.location == at(3, 8) and "define cycle: a -> b -> a" in str(error)


def test_define_containing_itself() -> None:
    error = error_of("define a model ( model( a( ) ) )\na( )")
    assert error.location == at(1, 25) and "contains itself" in str(error)


def test_block_outside_a_model() -> None:
    assert error_of("block( points 3 )").location == at(1, 1)


def test_sensor_outside_a_ranger() -> None:
    error = error_of("position(\n  sensor( )\n)")
    assert error.location == at(2, 3) and "'sensor' outside a ranger" in str(error)


def test_window_inside_a_model() -> None:
    assert error_of("model( window( ) )").location == at(1, 8)


def test_entity_inside_a_block() -> None:
    error = error_of("model( block( points 3 model( ) ) )")
    assert error.location == at(1, 24) and "'block' cannot contain entities" in str(error)


def test_entity_inside_a_sensor() -> None:
    assert error_of("ranger( sensor( model( ) ) )").location == at(1, 17)


def test_too_few_tuple_values() -> None:
    error = error_of("model(\n  size [0.01]\n)")
    assert error.location == at(2, 3)
    assert "found 1 values, expected 3 values" in str(error)


def test_empty_scalar_tuple() -> None:
    assert "found 0 values, expected 1 value" in str(error_of("resolution [ ]"))


def test_too_few_pose_values() -> None:
    assert "found 2 values, expected 4 values" in str(error_of("model( pose [1 2] )"))


def test_too_few_velocity_bounds() -> None:
    error = error_of("position( velocity_bounds [-1 1 -1 1] )")
    assert error.location == at(1, 11) and "expected 8 values" in str(error)


def test_too_few_odom_error_values() -> None:
    assert "expected 4 values" in str(error_of("position( odom_error [0.1 0.1 0] )"))


def test_string_where_a_number_is_needed() -> None:
    error = error_of('model( size [1 "two" 3] )')
    assert error.location == at(1, 16) and 'found string "two", expected a number' in str(error)


def test_unknown_drive() -> None:
    error = error_of('position( drive "tank" )')
    assert error.location == at(1, 17) and '"diff" or "omni" or "car"' in str(error)


def test_unknown_localization() -> None:
    assert error_of('position( localization "slam" )').location == at(1, 24)


def test_unknown_units() -> None:
    assert error_of('unit_length "km"').location == at(1, 13)
    assert error_of('a 1\nunit_angle "grad"').location == at(2, 12)


def test_block_without_points() -> None:
    assert error_of("model(\n block( z [0 1] )\n)").location == at(2, 2)


def test_block_missing_a_point() -> None:
    error = error_of("model( block( points 4 point[0] [0 0] point[1] [1 0] point[2] [1 1] ) )")
    assert error.location == at(1, 15)
    assert "block is missing point[3]" in str(error) and "found 3 points, expected 4 points" in str(error)


def test_block_with_too_few_points() -> None:
    assert error_of("model( block( points 2 point[0] [0 0] point[1] [1 0] ) )").location == at(1, 15)


def test_block_point_with_one_coordinate() -> None:
    assert error_of("model( block( points 3 point[0] [0] point[1] [1 0] point[2] [1 1] ) )").location == at(1, 24)


def test_block_with_inverted_z() -> None:
    assert error_of("model( block( points 3 point[0] [0 0] point[1] [1 0] point[2] [1 1] z [1 0] ) )").location == at(
        1, 69
    )


def test_missing_bitmap_names_the_tried_path_and_the_key(tmp_path: Path) -> None:
    world = tmp_path / "worlds" / "w.world"
    world.parent.mkdir()
    world.write_text('model(\n  bitmap "../maps/none.png"\n)\n')
    with pytest.raises(WorldError) as info:
        load_world(world)
    assert info.value.location == SourceLocation(str(world), 2, 3)
    assert str(tmp_path / "maps" / "none.png") in str(info.value)


def test_unreadable_bitmap(tmp_path: Path) -> None:
    (tmp_path / "bad.png").write_text("not an image")
    with pytest.raises(WorldError) as info:
        load_world_text('model( bitmap "bad.png" )', tmp_path / "w.world")
    assert "bad.png" in str(info.value)


@pytest.mark.parametrize(
    ("text", "column"),
    [
        ("resolution 0", 1),
        ("interval_sim -5", 1),
        ("ranger( sensor( samples 0 ) )", 17),
        ("ranger( sensor( range [3 1] ) )", 17),
        ("ranger( sensor( fov -10 ) )", 17),
        ("model( size [1 -1 1] )", 8),
        ("model( update_interval 0 )", 8),
        ("position( wheelbase 0 )", 11),
        ("position( velocity_bounds [1 -1 -1 1 -1 1 -90 90] )", 11),
        ("laser( samples 0 )", 8),
        ("laser( range_min 10 )", 8),
        ("laser( range_max 0 )", 8),
    ],
)
def test_values_that_cannot_work(text: str, column: int) -> None:
    assert error_of(text).location == at(1, column)


def test_number_out_of_range() -> None:
    error = error_of("model( size [1" + "0" * 400 + " 1 1] )")
    assert error.location == at(1, 14) and "finite" in str(error)


def test_missing_world_file(tmp_path: Path) -> None:
    """As on the command line: no line to point at, the path and what was tried instead."""
    with pytest.raises(WorldError) as info:
        load_world(tmp_path / "none.world")
    assert info.value.location is None
    assert str(info.value).startswith(f"world file not found: {tmp_path / 'none.world'} (no such file; bundled worlds")


def test_undecodable_bytes_are_reported_where_they_are(tmp_path: Path) -> None:
    world = tmp_path / "w.world"
    world.write_bytes(b'model(\n  name "ok" \xff\n)\n')
    with pytest.raises(WorldError) as info:
        load_world(world)
    assert info.value.location == SourceLocation(str(world), 2, 13)
