"""World file → WorldDescription: defines, units, defaults, names, bodies, positions, rangers, Stage 3."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from stage_sim.worldfile.description import Model, Pose, PositionSettings, Sensor, WorldDescription
from stage_sim.worldfile.errors import SourceLocation
from stage_sim.worldfile.loader import load_world, load_world_text

DEG = math.pi / 180

ROOMS_WORLD = """\
# Syntax of .world file for Stage simulator can be found here:
# http://rtv.github.io/Stage/modules.html

define floorplan model (
    color "SlateGray"
    boundary 1
    gui_nose 1
    gui_grid 0
    gui_move 0
    obstacle_return 1
)

window(
    size [700 650 1]
    rotate [ 0 0]
    center [ 13.525 10.825 0 ]
    scale 25
    show_data 1
    show_clock 1
)

floorplan (
    size [27.05 21.65 1.000]
    pose [13.525 10.825 0.000 0.000]
    bitmap "../maps/rooms.png"
)

include "../robots/simple_robot.inc"

simple_robot (pose [ 11.1 9.2 0.000 90.000 ] name "robot")
"""

SIMPLE_ROBOT_INC = """\
define laser ranger(
  sensor(
    range [ 0.0 5.6 ]
    fov 240.0
    samples 240
  )
  color "blue"
  size [ 0.06 0.06 0.06 ]
  block( points 4
    point[0] [0 0]
    point[1] [0 1]
    point[2] [1 1]
    point[3] [1 0]
    z [0 1]
  )
)

define simple_robot position(
  odom_error [0.03 0.03 0.00 0.05]
  localization "odom"
  size [ 0.4 0.3 0.2 ]
  gui_nose 1
  drive "diff"
  color "red"
  laser(pose [ 0.23 0.0 -0.15 0.0 ])
)
"""

# navigation_tutorials' willow-pr2.world as shown in the course slides.
WILLOW_PR2_WORLD = """\
define block model
(
  size [0.5 0.5 0.5]
  gui_nose 0
)

define topurg ranger
(
  sensor(
    range_max 30.0
    fov 270.25
    samples 1081
  )
  # generic model properties
  color "black"
  size [ 0.05 0.05 0.1 ]
)

define pr2 position
(
  size [0.65 0.65 0.25]
  origin [-0.05 0 0 0]
  gui_nose 1
  drive "omni"
  topurg(pose [ 0.275 0.000 0 0.000 ])
)

define floorplan model
(
  # sombre, sensible, artistic
  color "gray30"

  # most maps will need a bounding box
  boundary 1

  gui_nose 0
  gui_grid 0

  gui_outline 0
  gripper_return 0
  fiducial_return 0
  ranger_return 1
)

# set the resolution of the underlying raytrace model in meters
resolution 0.02

interval_sim 100  # simulation timestep in milliseconds


window
(
  size [ 745.000 448.000 ]

  rotate [ 0.000 0.000 ]
  scale 28.806
)

# load an environment bitmap
floorplan
(
  name "willow"
  bitmap "../maps/willow-full.pgm"
  size [58.4 52.6 0.5]
  pose [ -26.300 29.200 0 90.000 ]
)

# throw in a robot
pr2( pose [ -26.068 12.140 0 87.363 ] name "pr2" color "blue")
block( pose [ -25.251 10.586 0 180.000 ] color "red")
"""


def write_image(path: Path, pixels: np.ndarray) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(pixels.astype(np.uint8)).save(path)


def framed(height: int, width: int) -> np.ndarray:
    """A white image with a black frame: occupied pixels on all four borders."""
    pixels = np.full((height, width), 255, np.uint8)
    pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
    return pixels


def write_rooms(root: Path) -> Path:
    """The course's rooms.world + simple_robot.inc with a tiny generated rooms.png; returns the world path."""
    (root / "worlds").mkdir(parents=True, exist_ok=True)
    (root / "robots").mkdir(parents=True, exist_ok=True)
    (root / "worlds" / "rooms.world").write_text(ROOMS_WORLD)
    (root / "robots" / "simple_robot.inc").write_text(SIMPLE_ROBOT_INC)
    pixels = framed(20, 30)
    pixels[5:10, 10] = 0
    write_image(root / "maps" / "rooms.png", pixels)
    return root / "worlds" / "rooms.world"


def write_willow(root: Path) -> Path:
    (root / "worlds").mkdir(parents=True, exist_ok=True)
    (root / "worlds" / "willow-pr2.world").write_text(WILLOW_PR2_WORLD)
    write_image(root / "maps" / "willow-full.pgm", framed(26, 29))
    return root / "worlds" / "willow-pr2.world"


def load(text: str) -> WorldDescription:
    return load_world_text(text, "/virtual/w.world")


def only(text: str) -> Model:
    world = load(text)
    assert len(world.models) == 1
    return world.models[0]


def messages(world: WorldDescription) -> list[str]:
    return [w.message for w in world.warnings]


# --- the course worlds -------------------------------------------------------------------------------


def test_rooms_world_from_the_course(tmp_path: Path) -> None:
    world = load_world(write_rooms(tmp_path))
    assert world.warnings == []
    assert world.settings.name == "rooms.world"
    window = world.settings.window
    assert window is not None and window.size == (700, 650) and window.center == (13.525, 10.825)
    assert window.scale == 25 and window.show_data

    floor, robot = world.models
    assert floor.type == "model" and floor.name == "model:0"
    assert floor.size == (27.05, 21.65, 1.0) and floor.pose == Pose(13.525, 10.825, 0, 0)
    assert floor.color == pytest.approx((112 / 255, 128 / 255, 144 / 255, 1.0))
    assert floor.boundary and not floor.gui_move and floor.gui_nose and floor.obstacle_return
    assert floor.blocks == [] and floor.bitmap is not None
    assert floor.bitmap.path == tmp_path / "maps" / "rooms.png"
    assert floor.bitmap.occupied.shape == (20, 30) and floor.bitmap.occupied[5:10, 10].all()
    assert floor.bitmap.grid is None
    assert floor.bitmap.location == SourceLocation(str(tmp_path / "worlds" / "rooms.world"), 25, 5)

    assert robot.type == "position" and robot.name == "robot"
    assert robot.pose.x == 11.1 and robot.pose.y == 9.2 and robot.pose.yaw == pytest.approx(math.pi / 2)
    assert robot.size == (0.4, 0.3, 0.2) and robot.color == (1, 0, 0, 1) and robot.gui_nose
    assert robot.position == PositionSettings(
        drive="diff", localization="odom", odom_error=(0.03, 0.03, 0.0, pytest.approx(0.05 * DEG))
    )
    assert robot.position.odom_error[3] == pytest.approx(0.000872665, abs=1e-9)
    assert len(robot.blocks) == 1  # default unit square

    (laser,) = robot.children
    assert laser.type == "ranger" and laser.name == "robot.ranger:0"
    assert laser.pose == Pose(0.23, 0.0, -0.15, 0.0) and laser.size == (0.06, 0.06, 0.06)
    assert laser.color == (0, 0, 1, 1)
    assert laser.sensors == [Sensor(range_min=0.0, range_max=5.6, fov=pytest.approx(240 * DEG), samples=240)]
    (block,) = laser.blocks
    np.testing.assert_array_equal(block.points, [[0, 0], [0, 1], [1, 1], [1, 0]])
    assert block.z == (0.0, 1.0)
    assert block.location.file == str(tmp_path / "robots" / "simple_robot.inc")
    assert [m.name for m in world.robots()] == ["robot"]


def test_willow_pr2_world_from_the_course(tmp_path: Path) -> None:
    path = write_willow(tmp_path)
    world = load_world(path)
    assert world.settings.resolution == 0.02 and world.settings.interval_sim == pytest.approx(0.1)
    assert world.settings.window is not None and world.settings.window.scale == 28.806

    willow, pr2, block = world.models
    assert willow.name == "willow" and willow.type == "model"
    assert willow.color == pytest.approx((77 / 255, 77 / 255, 77 / 255, 1.0))
    assert willow.pose == Pose(-26.3, 29.2, 0, pytest.approx(math.pi / 2))
    assert willow.bitmap is not None and willow.bitmap.occupied.shape == (26, 29)
    assert willow.size == (58.4, 52.6, 0.5) and willow.boundary and willow.blocks == []

    assert pr2.name == "pr2" and pr2.type == "position" and pr2.color == (0, 0, 1, 1)
    assert pr2.position is not None and pr2.position.drive == "omni" and pr2.position.odom_error is None
    assert pr2.origin == Pose(-0.05, 0, 0, 0) and pr2.size == (0.65, 0.65, 0.25)
    assert pr2.pose.yaw == pytest.approx(87.363 * DEG)
    (topurg,) = pr2.children
    assert topurg.type == "ranger" and topurg.name == "pr2.ranger:0" and topurg.size == (0.05, 0.05, 0.1)
    assert topurg.color == (0, 0, 0, 1) and topurg.pose.x == 0.275
    (sensor,) = topurg.sensors
    assert sensor.range_max == 5.0 and sensor.range_min == 0.0  # range_max 30 is ignored, as in Stage 4
    assert sensor.samples == 1081 and sensor.fov == pytest.approx(270.25 * DEG)

    # `define block model` shadows the built-in block: the last line is a child-less model.
    assert block.type == "model" and block.name == "model:1" and block.size == (0.5, 0.5, 0.5)
    assert block.color == (1, 0, 0, 1) and block.pose.yaw == pytest.approx(math.pi) and len(block.blocks) == 1

    (warning,) = world.warnings
    assert "range_max" in warning.message and "[0 5]" in warning.message
    assert warning.location == SourceLocation(str(path), 10, 5)


# --- defaults ----------------------------------------------------------------------------------------


def test_world_defaults() -> None:
    world = load("")
    settings = world.settings
    assert settings.name == "w.world" and settings.resolution == 0.02 and settings.interval_sim == 0.1
    assert settings.quit_time == 0 and settings.speedup == 1 and settings.threads == 1
    assert settings.unit_length == 1.0 and settings.unit_angle == DEG and settings.window is None
    assert world.models == [] and world.warnings == []


def test_world_keys() -> None:
    world = load('name "lab"\nresolution 0.05\ninterval_sim 50\nquit_time 12\nspeedup -1\nthreads 0\nshow_clock 1')
    settings = world.settings
    assert settings.name == "lab" and settings.resolution == 0.05 and settings.interval_sim == 0.05
    assert settings.quit_time == 12 and settings.speedup == -1 and settings.threads == 1
    assert world.warnings == []


def test_model_defaults() -> None:
    model = only("model( )")
    assert model.name == "model:0" and model.pose == Pose() and model.origin == Pose()
    assert model.size == (0.4, 0.4, 1.0) and model.color == (1, 0, 0, 1)
    assert model.obstacle_return and model.ranger_return == 1.0 and model.update_interval == 0.1
    assert model.stack_children and model.gui_move and not model.gui_nose and not model.boundary
    assert model.position is None and model.sensors == [] and model.bitmap is None
    (block,) = model.blocks  # Stage's default unit square
    np.testing.assert_array_equal(block.points, [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    assert block.z == (0.0, 1.0)


def test_position_defaults() -> None:
    robot = only("position( )")
    assert robot.position == PositionSettings()
    assert robot.position.odom_error is None and robot.position.velocity_bounds[7] == pytest.approx(math.pi / 2)
    assert len(robot.blocks) == 1


def test_ranger_defaults_have_no_body_and_small_size() -> None:
    world = load("position( ranger( sensor( ) ) )")
    ranger = world.models[0].children[0]
    assert ranger.size == (0.15, 0.15, 0.2) and ranger.blocks == [] and not ranger.gui_move
    assert ranger.color == pytest.approx((0, 0, 139 / 255, 1))
    assert ranger.sensors == [Sensor()]
    assert ranger.sensors[0].fov == 0.1  # radians, not degrees
    assert (ranger.sensors[0].range_min, ranger.sensors[0].range_max, ranger.sensors[0].samples) == (0, 5, 1)


def test_model_keys() -> None:
    model = only(
        "model( pose [1 2 0.5 45] size [2 3 4] origin [0.1 0.2 0.3 90] boundary 1 obstacle_return 0 "
        "ranger_return -1 update_interval 50 stack_children 0 gui_nose 1 gui_outline 1 gui_grid 1 gui_move 0 "
        "mass 3 fiducial_return 2 )"
    )
    assert model.pose == Pose(1, 2, 0.5, pytest.approx(math.pi / 4))
    assert model.size == (2, 3, 4) and model.origin == Pose(0.1, 0.2, 0.3, pytest.approx(math.pi / 2))
    assert model.boundary and not model.obstacle_return and model.ranger_return == -1
    assert model.update_interval == 0.05 and not model.stack_children
    assert model.gui_nose and model.gui_outline and model.gui_grid and not model.gui_move


def test_duplicate_keys_last_one_wins() -> None:
    model = only('model( size [1 1 1] color "blue" size [2 2 2] name "a" name "b" )')
    assert model.size == (2, 2, 2) and model.name == "b"


def test_extra_tuple_values_are_ignored() -> None:
    model = only("model( size [1 2 3 4 5] pose [1 2 3 4 5] )")
    assert model.size == (1, 2, 3) and model.pose.z == 3


def test_integer_keys_use_atoi() -> None:
    ranger = load("ranger( sensor( samples 10.9 ) )").models[0]
    assert ranger.sensors[0].samples == 10


def test_malformed_number_is_read_like_atof_with_a_warning() -> None:
    world = load("model( size [1.2.3 1 1] )")
    assert world.models[0].size == (1.2, 1, 1)
    assert "number '1.2.3' read as 1.2" in messages(world)[0]


# --- defines -----------------------------------------------------------------------------------------


def test_define_chain_applies_base_first_then_derived_then_instance() -> None:
    world = load(
        'define a model ( size [1 1 1] color "green" pose [1 0 0 0] model( name "from_a" ) )\n'
        'define b a ( size [2 2 2] pose [2 0 0 0] model( name "from_b" ) )\n'
        "define c b ( size [3 3 3] )\n"
        'c( pose [4 0 0 0] model( name "from_instance" ) )\n'
    )
    (model,) = world.models
    assert model.type == "model" and model.size == (3, 3, 3) and model.pose.x == 4
    assert model.color == (0, 1, 0, 1)
    assert [c.name for c in model.children] == ["from_a", "from_b", "from_instance"]


def test_define_may_use_a_define_that_comes_later_but_before_the_instance() -> None:
    world = load("define robot position ( eye( ) )\ndefine eye ranger ( sensor( ) )\nrobot( )")
    assert world.models[0].children[0].type == "ranger"


def test_define_named_like_a_builtin_shadows_it_from_there_on() -> None:
    text = (
        "model( block( points 3 point[0] [0 0] point[1] [1 0] point[2] [0 1] ) )\n"
        "define block model ( size [0.5 0.5 0.5] )\n"
        "model( block( pose [1 0 0 0] ) )\n"
        "block( )\n"
    )
    first, second, third = load(text).models
    assert len(first.blocks) == 1 and first.blocks[0].points.shape == (3, 2) and first.children == []
    assert [c.type for c in second.children] == ["model"] and second.children[0].size == (0.5, 0.5, 0.5)
    assert third.type == "model" and third.name == "model:2"


def test_instances_share_the_define_properties_including_name() -> None:
    world = load('define r position ( name "same" )\nr( )\nr( )')
    assert [m.name for m in world.models] == ["same", "same"]
    assert "used more than once" in messages(world)[0]


def test_sensor_define_inside_ranger() -> None:
    world = load("define sick sensor ( samples 361 fov 180 range [0 30] )\nranger( sick( ) sick( samples 5 ) )")
    sensors = world.models[0].sensors
    assert [s.samples for s in sensors] == [361, 5]
    assert sensors[0].range_max == 30 and sensors[0].fov == pytest.approx(math.pi)


def test_redefinition_replaces_and_warns() -> None:
    world = load("define a model ( size [1 1 1] )\na( )\ndefine a model ( size [2 2 2] )\na( )")
    assert [m.size for m in world.models] == [(1, 1, 1), (2, 2, 2)]
    assert "redefined" in messages(world)[0]


def test_define_of_itself_as_parent_means_the_builtin() -> None:
    assert only("define model model ( size [1 2 3] )\nmodel( )").size == (1, 2, 3)


def test_warnings_from_a_define_are_reported_once() -> None:
    world = load('define r position ( colour "x" )\nr( )\nr( )\nr( )')
    assert messages(world).count("unknown key 'colour' in a position model ignored") == 1


# --- names and order ---------------------------------------------------------------------------------


def test_stage_tokens_count_per_type_and_per_parent() -> None:
    world = load('model( )\nposition( name "bob" model( ) ranger( ) model( ) )\nmodel( )\nposition( ranger( ) )\n')
    names = [m.name for m in world.walk()]
    assert names == [
        "model:0", "bob", "bob.model:0", "bob.ranger:0", "bob.model:1", "model:1", "position:1",
        "position:1.ranger:0",
    ]  # fmt: skip


def test_robots_are_position_models_in_pre_order() -> None:
    world = load('model( position( name "inner" ) )\nposition( name "outer" position( name "child" ) )')
    assert [m.name for m in world.robots()] == ["inner", "outer", "child"]


# --- units -------------------------------------------------------------------------------------------


def test_unit_length_and_angle_apply_to_every_listed_key() -> None:
    world = load(
        'unit_length "cm"\nunit_angle "radians"\n'
        "position( pose [100 200 10 1.5] size [40 40 20] origin [1 2 3 0.5] wheelbase 50 "
        "velocity_bounds [-100 100 -50 50 -1 1 -2 2] acceleration_bounds [-10 10 -10 10 -10 10 -3 3] "
        "odom_error [0.1 0.2 0.3 0.4] localization_origin [10 20 0 0.25] "
        "block( points 3 point[0] [0 0] point[1] [100 0] point[2] [0 100] z [0 50] ) "
        "ranger( sensor( pose [5 0 0 0.1] size [2 2 2] range [10 500] fov 3.0 noise [0.01 0.02 0.5] ) ) )"
    )
    assert world.settings.unit_length == 0.01 and world.settings.unit_angle == 1.0
    robot = world.models[0]
    assert robot.pose == Pose(1.0, 2.0, 0.1, 1.5) and robot.size == pytest.approx((0.4, 0.4, 0.2))
    assert robot.origin == Pose(0.01, 0.02, 0.03, 0.5)
    pos = robot.position
    assert pos is not None and pos.wheelbase == 0.5
    assert pos.velocity_bounds == pytest.approx((-1, 1, -0.5, 0.5, -0.01, 0.01, -2, 2))
    assert pos.acceleration_bounds == pytest.approx((-0.1, 0.1, -0.1, 0.1, -0.1, 0.1, -3, 3))
    assert pos.odom_error == (0.1, 0.2, 0.3, 0.4)  # literal; the angle is already in radians
    assert pos.localization_origin == Pose(0.1, 0.2, 0.0, 0.25)
    np.testing.assert_allclose(robot.blocks[0].points, [[0, 0], [1, 0], [0, 1]])
    assert robot.blocks[0].z == (0.0, 0.5)
    sensor = robot.children[0].sensors[0]
    assert sensor.pose == Pose(0.05, 0, 0, 0.1) and sensor.size == (0.02, 0.02, 0.02)
    assert (sensor.range_min, sensor.range_max) == (0.1, 5.0) and sensor.fov == 3.0
    assert sensor.noise == (0.01, 0.02, 0.5)


def test_degrees_convert_angles_but_not_lengths() -> None:
    robot = only(
        "position( velocity_bounds [-2 2 -1 1 -1 1 -45 45] odom_error [0.03 0.03 0 0.05] "
        "ranger( sensor( noise [0.1 0.2 10] ) ) )"
    )
    assert robot.position is not None
    assert robot.position.velocity_bounds == pytest.approx((-2, 2, -1, 1, -1, 1, -math.pi / 4, math.pi / 4))
    assert robot.position.odom_error == pytest.approx((0.03, 0.03, 0, 0.05 * DEG))
    assert robot.children[0].sensors[0].noise == pytest.approx((0.1, 0.2, 10 * DEG))


def test_millimetres_and_unit_keys_after_the_models() -> None:
    world = load('model( size [1000 500 250] )\nunit_length "mm"')
    assert world.models[0].size == pytest.approx((1.0, 0.5, 0.25))


# --- bodies ------------------------------------------------------------------------------------------


def test_blocks_keep_points_in_order_and_replace_the_default_body() -> None:
    model = only(
        "model( block( points 4 point[3] [0 1] point[0] [0 0] point[1] [2 0] point[2] [2 1] z [0.1 0.4] )\n"
        "       block( points 3 point[0] [0 0] point[1] [1 0] point[2] [0 1] ) )"
    )
    assert len(model.blocks) == 2
    np.testing.assert_array_equal(model.blocks[0].points, [[0, 0], [2, 0], [2, 1], [0, 1]])
    assert model.blocks[0].points.dtype == float and model.blocks[0].z == (0.1, 0.4)
    assert model.blocks[1].z == (0.0, 1.0)
    assert model.blocks[0].location == SourceLocation("/virtual/w.world", 1, 8)


def test_points_beyond_the_count_are_ignored_with_a_warning() -> None:
    world = load("model( block( points 3 point[0] [0 0] point[1] [1 0] point[2] [0 1] point[3] [5 5] ) )")
    assert world.models[0].blocks[0].points.shape == (3, 2)
    assert "point[3] ignored" in messages(world)[0]


def test_bodiless_types_get_no_default_block() -> None:
    world = load("camera( )\nfiducial( )\nranger( sensor( ) )")
    assert all(m.blocks == [] for m in world.models)
    assert world.models[0].size == (0.1, 0.07, 0.05)


def test_position_with_blocks_has_only_those() -> None:
    robot = only("position( block( points 3 point[0] [0 0] point[1] [1 0] point[2] [0 1] ) )")
    assert len(robot.blocks) == 1 and robot.blocks[0].points.shape == (3, 2)


def test_bitmap_is_relative_to_the_world_file_and_removes_the_default_body(tmp_path: Path) -> None:
    pixels = np.full((4, 6), 255, np.uint8)
    pixels[1, 2] = 0
    pixels[3, 5] = 127  # <= 127 is occupied
    write_image(tmp_path / "maps" / "m.png", pixels)
    world = load_world_text('model( bitmap "maps/m.png" )\nmodel( bitmap "maps/m.png" )', tmp_path / "w.world")
    first, second = world.models
    assert first.blocks == [] and first.bitmap is not None
    expected = np.zeros((4, 6), bool)
    expected[1, 2] = expected[3, 5] = True
    np.testing.assert_array_equal(first.bitmap.occupied, expected)
    assert second.bitmap is first.bitmap  # loaded once


def test_absolute_bitmap_path(tmp_path: Path) -> None:
    write_image(tmp_path / "a.pgm", framed(3, 3))
    model = only(f'model( bitmap "{tmp_path / "a.pgm"}" )')
    assert model.bitmap is not None and model.bitmap.path == tmp_path / "a.pgm"


def test_yaml_bitmap_uses_map_server_semantics(tmp_path: Path) -> None:
    pixels = np.full((3, 4), 254, np.uint8)
    pixels[0, 0] = 0  # top-left pixel occupied
    pixels[2, 3] = 205  # unknown in map_server terms
    write_image(tmp_path / "map.pgm", pixels)
    (tmp_path / "map.yaml").write_text(
        "image: map.pgm\nresolution: 0.5\norigin: [-1.0, -2.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    world = load_world_text('model( bitmap "map.yaml" )', tmp_path / "w.world")
    bitmap = world.models[0].bitmap
    assert bitmap is not None and bitmap.grid is not None
    assert bitmap.grid.resolution == 0.5 and bitmap.grid.origin == (-1.0, -2.0, 0.0)
    assert bitmap.grid.values[2, 0] == 100 and bitmap.grid.values[0, 3] == -1  # grid row 0 = bottom
    expected = np.zeros((3, 4), bool)
    expected[0, 0] = True  # image row order
    np.testing.assert_array_equal(bitmap.occupied, expected)


# --- position ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("drive", ["diff", "omni", "car"])
def test_drives(drive: str) -> None:
    robot = only(f'position( drive "{drive}" wheelbase 0.3 )')
    assert robot.position is not None and robot.position.drive == drive and robot.position.wheelbase == 0.3


def test_localization_and_origin() -> None:
    robot = only('position( localization "odom" localization_origin [1 2 0 90] )')
    assert robot.position is not None and robot.position.localization == "odom"
    assert robot.position.localization_origin == Pose(1, 2, 0, pytest.approx(math.pi / 2))


# --- rangers -----------------------------------------------------------------------------------------


def test_ranger_with_several_sensors() -> None:
    ranger = only(
        "ranger( sensor( pose [0.1 0 0 90] size [0.01 0.02 0.03] range [0.2 4] fov 30 samples 3 "
        'noise [0.01 0.02 2] color "green" ) sensor( color_rgba [0.1 0.2 0.3 0.4] ) )'
    )
    first, second = ranger.sensors
    assert first == Sensor(
        pose=Pose(0.1, 0, 0, pytest.approx(math.pi / 2)), size=(0.01, 0.02, 0.03), range_min=0.2, range_max=4,
        fov=pytest.approx(math.pi / 6), samples=3, noise=(0.01, 0.02, pytest.approx(2 * DEG)), color=(0, 1, 0, 1),
    )  # fmt: skip
    assert second.color == (0.1, 0.2, 0.3, 0.4) and second.samples == 1


def test_ranger_level_keys_become_the_single_sensor_with_a_warning() -> None:
    world = load("ranger( range [0 8] fov 180 samples 181 noise [0.1 0 0] )")
    (sensor,) = world.models[0].sensors
    assert sensor.range_max == 8 and sensor.fov == pytest.approx(math.pi) and sensor.samples == 181
    assert sensor.noise == (0.1, 0, 0)
    (warning, stray) = world.warnings  # a ranger on no robot is also said to produce no scans
    assert "single sensor" in warning.message and "outside sensor( )" in warning.message
    assert warning.location == SourceLocation("/virtual/w.world", 1, 9)
    assert "is not simulated: it sits at the top level" in stray.message


def test_ranger_level_keys_next_to_sensors_are_ignored() -> None:
    world = load("ranger( samples 99 sensor( samples 3 ) )")
    assert [s.samples for s in world.models[0].sensors] == [3]
    assert "ranger-level 'samples' ignored" in messages(world)[0]


def test_ranger_without_sensors_warns() -> None:
    world = load("ranger( )")
    assert world.models[0].sensors == [] and "no scans" in messages(world)[0]


# --- Stage 3 leftovers -------------------------------------------------------------------------------


def test_stage3_laser_model_defaults() -> None:
    world = load("position( laser( ) )")
    laser = world.models[0].children[0]
    assert laser.type == "ranger" and laser.name == "position:0.ranger:0"
    assert laser.sensors == [Sensor(samples=180, range_max=8.0, fov=pytest.approx(math.pi))]
    (warning,) = world.warnings
    assert "Stage 3 'laser'" in warning.message and "180 samples" in warning.message
    assert "Stage 4 has no 'laser' type" in warning.message


def test_stage3_laser_model_keys() -> None:
    world = load("laser( samples 361 range_max 30 range_min 0.1 fov 270 resolution 2 laser_return 1 )")
    (sensor,) = world.models[0].sensors
    assert (sensor.samples, sensor.range_min, sensor.range_max) == (361, 0.1, 30)
    assert sensor.fov == pytest.approx(270 * DEG)
    assert any("'resolution' ignored" in m for m in messages(world))


def test_stage3_laser_with_sensor_blocks_uses_them() -> None:
    world = load("laser( samples 361 sensor( samples 5 ) )")
    assert [s.samples for s in world.models[0].sensors] == [5]
    assert "with its sensor( ) blocks" in messages(world)[0]


@pytest.mark.parametrize("key", ["range_max 30", "range_min 1", "laser_return 1", "view 1", "resolution 1"])
def test_stage3_keys_inside_rangers_and_sensors_are_ignored(key: str) -> None:
    world = load(f"ranger( {key} sensor( {key} ) )")
    assert world.models[0].sensors == [Sensor()]
    name = key.split()[0]
    assert [m.startswith(f"Stage 3 key '{name}' ignored") for m in messages(world)] == [True, True, False]
    assert messages(world)[2].startswith("ranger 'ranger:0' is not simulated: it sits at the top level")


def test_size3_origin3_and_interval_real() -> None:
    world = load("interval_real 100\nmodel( size3 [1 2 3] origin3 [0.5 0 0 0] )")
    model = world.models[0]
    assert model.size == (1, 2, 3) and model.origin.x == 0.5
    text = messages(world)
    assert any("'size3' read as 'size'" in m for m in text) and any("'origin3' read as 'origin'" in m for m in text)
    assert any("'interval_real' ignored" in m for m in text)


def test_three_element_pose_reads_as_x_y_0_a() -> None:
    world = load("model( pose [1 2 90] )")
    assert world.models[0].pose == Pose(1, 2, 0, pytest.approx(math.pi / 2))
    assert "[x y 0 a]" in messages(world)[0]


# --- other types, unknown keys, colours, window ------------------------------------------------------


@pytest.mark.parametrize(
    "kind",
    ["camera", "fiducial", "blobfinder", "gripper", "actuator", "bumper", "blinkenlight", "lightindicator", "wifi"],
)
def test_unsupported_types_load_with_a_not_simulated_warning(kind: str) -> None:
    world = load(f"position( {kind}( range [0 5] fov 60 ) )")
    child = world.models[0].children[0]
    assert child.type == kind
    assert messages(world) == [f"'{kind}' models are not simulated (loaded, but produce no data)"]
    assert world.warnings[0].location == SourceLocation("/virtual/w.world", 1, 11)


def test_each_unsupported_type_warns_once_per_world_naming_the_count() -> None:
    world = load(
        "define bot position ( fiducial( ) camera( ) )\n"
        + "bot( )\n" * 3
        + 'wifi( ip "10.0.0.1" mac "00:03" essid "net" model "simple" range 4 )\n'
    )
    assert messages(world) == [
        "'fiducial' models are not simulated (loaded, but produce no data); 3 in this world, the first here",
        "'camera' models are not simulated (loaded, but produce no data); 3 in this world, the first here",
        "'wifi' models are not simulated (loaded, but produce no data)",
    ]
    assert [w.location.column for w in world.warnings] == [23, 35, 1]
    assert sum(m.type == "fiducial" for m in world.walk()) == 3


def test_stage3_two_value_size_gets_the_default_height_with_a_warning() -> None:
    world = load("model( size [2 3] )\nranger( size [0.1 0.2] )")
    assert world.models[0].size == (2, 3, 1.0) and world.models[1].size == (0.1, 0.2, 0.2)
    assert messages(world)[0] == "Stage 3 size [x y] read as [x y 1] (Stage 4 refuses fewer than 3 values)"


def test_unknown_keys_warn_with_their_location() -> None:
    world = load('model(\n  colour "red"\n)\nfoo 1\nwindow( bar 2 )\nranger( sensor( baz 1 ) )')
    found = {(w.message, w.location.line, w.location.column) for w in world.warnings}
    assert ("unknown key 'colour' in a model model ignored", 2, 3) in found
    assert ("unknown key 'foo' in the world ignored", 4, 1) in found
    assert ("unknown key 'bar' in the window ignored", 5, 9) in found
    assert ("unknown key 'baz' in a sensor ignored", 6, 17) in found


def test_velocity_and_ctrl_warn() -> None:
    world = load('position( velocity [1 0 0 0] ctrl "wander" )')
    assert len(world.warnings) == 2 and all("not supported" in m for m in messages(world))


@pytest.mark.parametrize(
    ("name", "rgb"),
    [
        ("red", (255, 0, 0)), ("green", (0, 255, 0)), ("blue", (0, 0, 255)), ("black", (0, 0, 0)),
        ("white", (255, 255, 255)), ("gray", (190, 190, 190)), ("grey", (190, 190, 190)),
        ("gray0", (0, 0, 0)), ("gray30", (77, 77, 77)), ("grey30", (77, 77, 77)), ("gray50", (127, 127, 127)),
        ("gray90", (229, 229, 229)), ("gray100", (255, 255, 255)), ("gray1", (3, 3, 3)),
        ("SlateGray", (112, 128, 144)), ("slate gray", (112, 128, 144)), ("DarkGray", (169, 169, 169)),
        ("LightGray", (211, 211, 211)), ("yellow", (255, 255, 0)), ("orange", (255, 165, 0)),
        ("cyan", (0, 255, 255)), ("magenta", (255, 0, 255)), ("brown", (165, 42, 42)),
        ("purple", (160, 32, 240)), ("pink", (255, 192, 203)), ("navy", (0, 0, 128)),
        ("DarkBlue", (0, 0, 139)), ("DarkGreen", (0, 100, 0)),
    ],
)  # fmt: skip
def test_x11_colours(name: str, rgb: tuple[int, int, int]) -> None:
    color = only(f'model( color "{name}" )').color
    assert tuple(round(c * 255) for c in color[:3]) == rgb and color[3] == 1.0


def test_random_colour_is_fixed_and_color_rgba_overrides() -> None:
    first, second, third = load('model( color "random" )\nmodel( color "random" )\nmodel( color_rgba [0 0.5 1 0.25]'
                                ' color "red" )').models  # fmt: skip
    assert first.color == second.color
    assert third.color == (0, 0.5, 1, 0.25)


def test_unknown_colour_warns_and_keeps_the_default() -> None:
    world = load('model( color "octarine" )')
    assert world.models[0].color == (1, 0, 0, 1) and "octarine" in messages(world)[0]


def test_only_the_first_window_is_used() -> None:
    world = load("window( scale 10 rotate [30 90] show_grid 0 show_trails 1 )\nwindow( scale 20 )")
    window = world.settings.window
    assert window is not None and window.scale == 10 and not window.show_grid and window.show_trails
    assert window.rotate == pytest.approx((math.pi / 6, math.pi / 2))
    (warning,) = world.warnings
    assert "only the first window" in warning.message and warning.location.line == 2
