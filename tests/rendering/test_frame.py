"""Rendering: pixel colours at known world points of small synthetic worlds, recordings and the CLI."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from stage_sim.cli import main
from stage_sim.rendering import Recorder, palette, render, renderer_for
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text

REPO = Path(__file__).resolve().parents[2]

# A 4 m × 4 m room of 0.2 m walls (the north one blue) at 20 px/m, so one pixel is one 5 cm cell. The robot
# sits on a pixel centre, facing +x; its one-beam laser at the robot centre hits the east wall at x = 3.8.
ROOM = """
resolution 0.05
interval_sim 100
window( scale 20 )
define wall model ( color "black" )
wall( name "south" size [4 0.2 1] pose [2 0.1 0 0] )
wall( name "west" size [0.2 4 1] pose [0.1 2 0 0] )
wall( name "east" size [0.2 4 1] pose [3.9 2 0 0] )
wall( name "north" size [4 0.2 1] pose [2 3.9 0 0] color "blue" )
define laser ranger ( sensor( range [0 {range_max}] fov 0 samples 1 ) color "blue" size [0.05 0.05 0.05] )
define bot position ( size [0.4 0.4 0.2] color "green" drive "{drive}" {laser} )
bot( pose [{x} {y} 0 {yaw}] )
"""
X, Y = 1.025, 1.025
GREEN = (0, 255, 0)
LASER_ON_FREE = palette.blend((0.0, 0.0, 1.0, palette.LASER_ALPHA))


def sim_of(x: float = X, y: float = Y, yaw: float = 0.0, range_max: float = 5.0, laser: bool = True,
           drive: str = "diff") -> Simulation:
    text = ROOM.format(x=x, y=y, yaw=yaw, range_max=range_max, drive=drive, laser="laser( )" if laser else "")
    return Simulation(load_world_text(text, "room.world"), seed=0)


def color_at(sim: Simulation, image: np.ndarray, x: float, y: float, scale: float | None = None) -> tuple[int, ...]:
    """The colour of world point (x, y) in ``image`` drawn at ``scale`` (None: the world's)."""
    row, col = renderer_for(sim).view(scale).pixel(x, y)
    return tuple(int(c) for c in image[row, col])


def test_frame_geometry_comes_from_the_window_scale_or_the_argument() -> None:
    sim = sim_of()
    image = render(sim)
    assert image.dtype == np.uint8 and image.ndim == 3 and image.shape[2] == 3
    rows, cols = sim.static.shape
    view = renderer_for(sim).view()
    assert (view.map_height, view.width) == (rows, cols)  # 20 px/m × 0.05 m cells: a pixel a cell
    assert image.shape[:2] == (view.height, view.width)
    assert render(sim, scale=40).shape[1] == 2 * cols
    assert renderer_for(sim).view(40).map_height == 2 * rows
    with pytest.raises(ValueError, match="scale"):
        render(sim, scale=-1.0)


def test_occupied_cells_in_their_model_colour_and_free_cells_light() -> None:
    sim = sim_of()
    for scale in (20, 40):
        image = render(sim, scale=scale)
        assert color_at(sim, image, 3.9, 2.0, scale) == (0, 0, 0)  # east wall, black
        assert color_at(sim, image, 2.0, 3.9, scale) == (0, 0, 255)  # north wall, blue
        assert color_at(sim, image, 2.0, 2.5, scale) == palette.FREE


def test_world_y_is_up() -> None:
    image = render(sim_of(x=2.0, y=3.0), lasers=False)
    blue_rows = np.flatnonzero(np.all(image == (0, 0, 255), axis=2).any(axis=1))
    green_rows = np.flatnonzero(np.all(image == GREEN, axis=2).any(axis=1))
    south_wall_rows = np.flatnonzero(np.all(image[:, 60] == (0, 0, 0), axis=1))
    assert blue_rows.max() < green_rows.min() and green_rows.max() < south_wall_rows.min()


def test_robot_body_in_its_colour_with_a_nose_along_its_heading() -> None:
    sim = sim_of(yaw=90)
    image = render(sim, scale=40, lasers=False)
    assert color_at(sim, image, X - 0.1, Y - 0.1, 40) == GREEN
    assert color_at(sim, image, X, Y + 0.15, 40) == palette.NOSE  # facing +y: the nose points up
    assert color_at(sim, image, X + 0.15, Y, 40) == GREEN
    assert color_at(sim, image, X, Y + 0.3, 40) == palette.FREE


def test_laser_rays_from_the_sensor_to_the_hit_and_to_range_max_on_a_miss() -> None:
    sim = sim_of()
    image = render(sim)
    assert color_at(sim, image, 2.5, Y) == pytest.approx(LASER_ON_FREE, abs=2)
    assert color_at(sim, image, X + sim.scans[0][0].ranges[0] - 0.05, Y) == pytest.approx(LASER_ON_FREE, abs=2)
    assert color_at(sim, image, 2.5, Y + 0.1) == palette.FREE
    assert color_at(sim, render(sim, lasers=False), 2.5, Y) == palette.FREE
    short = sim_of(range_max=1.0)
    image = render(short)
    assert color_at(short, image, X + 0.9, Y) == pytest.approx(LASER_ON_FREE, abs=2)
    assert color_at(short, image, X + 1.1, Y) == palette.FREE


def test_trails_are_drawn_in_the_lightened_robot_colour_and_break_at_nan() -> None:
    sim = sim_of()
    trail = np.array([[0.5, 2.5], [1.5, 2.5], [np.nan, np.nan], [2.5, 2.5], [3.5, 2.5]])
    image = render(sim, trails=[trail])
    assert color_at(sim, image, 1.0, 2.5) == palette.trail_color(GREEN)
    assert color_at(sim, image, 3.0, 2.5) == palette.trail_color(GREEN)
    assert color_at(sim, image, 2.0, 2.5) == palette.FREE


def test_grid_lines_on_free_space_only() -> None:
    sim = sim_of()
    image = render(sim, grid=True)
    assert color_at(sim, image, 2.0, 2.5) == palette.GRID
    assert color_at(sim, image, 2.5, 2.5) == palette.FREE
    assert color_at(sim, image, 2.0, 3.9) == (0, 0, 255)


def test_clock_changes_with_sim_time_and_nothing_else_does() -> None:
    sim = sim_of()
    before = render(sim)
    sim.step()
    after = render(sim)
    changed = np.flatnonzero(np.any(before != after, axis=(1, 2)))
    assert changed.size and changed.min() >= renderer_for(sim).view().map_height


def test_gif_frames_per_interval_all_the_size_of_a_render(tmp_path: Path) -> None:
    sim = sim_of()
    sim.set_velocity(0, 0.3, 0.0, 0.0)
    recorder = Recorder(sim, tmp_path / "run.gif", every_s=0.5, fps=4)
    for _ in range(30):  # 3 s of sim time: frames at 0, 0.5, ..., 3.0
        sim.step()
        recorder.capture_if_due()
    recorder.close()
    gif = Image.open(tmp_path / "run.gif")
    assert gif.n_frames == 3.0 / 0.5 + 1 == recorder.frame_count
    assert gif.info["duration"] == 250 and gif.info["loop"] == 0
    height, width = render(sim).shape[:2]
    for k in range(gif.n_frames):
        gif.seek(k)
        assert gif.size == (width, height)


def test_png_is_the_final_frame(tmp_path: Path) -> None:
    sim = sim_of()
    sim.set_velocity(0, 0.3, 0.0, 0.2)
    recorder = Recorder(sim, tmp_path / "last.png", every_s=0.5, trail_s=0.0)
    for _ in range(7):  # ends between two due frames: close() adds the final state
        sim.step()
        recorder.capture_if_due()
    recorder.close()
    assert np.array_equal(np.array(Image.open(tmp_path / "last.png").convert("RGB")), render(sim))


def test_recorded_trail_follows_the_robot_and_skips_a_reset_jump(tmp_path: Path) -> None:
    sim = sim_of(laser=False, drive="omni")
    recorder = Recorder(sim, tmp_path / "trail.png", trail_s=100.0, lasers=False)
    for velocity in ((0.0, 0.5), (0.5, 0.0)):  # 2 s up to (X, Y + 1), 2 s right to (X + 1, Y + 1)
        sim.set_velocity(0, *velocity, 0.0)
        for _ in range(20):
            sim.step()
            recorder.capture_if_due()
    sim.reset_positions()  # back to (X, Y): the jump is not part of the path
    sim.step()
    recorder.capture_if_due()
    recorder.close()
    image = np.array(Image.open(tmp_path / "trail.png").convert("RGB"))
    assert color_at(sim, image, X, Y + 0.6) == palette.trail_color(GREEN)
    assert color_at(sim, image, X + 0.6, Y + 1.0) == palette.trail_color(GREEN)
    assert color_at(sim, image, X + 0.5, Y + 0.5) == palette.FREE


def test_recorder_rejects_other_formats(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"\.gif or \.png"):
        Recorder(sim_of(), tmp_path / "run.mp4")


def test_cli_renders_a_png_and_records_a_gif(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    world = tmp_path / "room.world"
    world.write_text(ROOM.format(x=X, y=Y, yaw=0, range_max=5.0, drive="diff", laser="laser( )"))
    assert main(["render", str(world), "-o", str(tmp_path / "room.png"), "--steps", "5", "--scale", "40"]) == 0
    png = Image.open(tmp_path / "room.png")
    assert png.size == (2 * 81, 2 * 81 + 2 * palette.CAPTION_LINE)  # narrow: the scale bar has its own line
    assert main(["render", str(world), "-o", str(tmp_path / "room.gif"), "--steps", "20", "--no-lasers"]) == 0
    assert Image.open(tmp_path / "room.gif").n_frames == 5
    assert "room.gif: 5 frame(s)" in capsys.readouterr().out


def test_cli_world_error_exits_2_with_a_message(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    world = tmp_path / "bad.world"
    world.write_text("resolution 0.05\nbot( pose [1 1 0 0 )\n")
    assert main(["render", str(world), "-o", str(tmp_path / "bad.png")]) == 2
    err = capsys.readouterr().err
    assert "bad.world:2" in err and "Traceback" not in err
    assert not (tmp_path / "bad.png").exists()


def test_the_core_imports_without_pillow_and_without_the_renderer() -> None:
    probe = (
        "import sys; sys.modules['PIL'] = None; import stage_sim.sim.simulation; "
        "assert 'stage_sim.rendering' not in sys.modules"
    )
    result = subprocess.run([sys.executable, "-c", probe], cwd=REPO, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
