"""Stage bitmap semantics: the first channel decides, ≤ 127 is occupied; the occupied box is found."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from stage_sim.worldfile.bitmap import load_stage_bitmap, occupied_bounding_box
from stage_sim.worldfile.errors import SourceLocation, WorldError


def save(tmp_path: Path, name: str, array: np.ndarray, mode: str | None = None) -> Path:
    path = tmp_path / name
    Image.fromarray(array.astype(np.uint8), mode=mode).save(path)
    return path


def test_threshold_127_is_occupied_128_is_free(tmp_path: Path) -> None:
    grey = np.array([[0, 127, 128, 255]])
    mask = load_stage_bitmap(save(tmp_path, "g.png", grey))
    assert mask.tolist() == [[True, True, False, False]]


def test_rgb_uses_the_red_channel_only_and_alpha_is_ignored(tmp_path: Path) -> None:
    rgba = np.array([[[0, 0, 255, 0], [255, 0, 0, 255], [100, 255, 255, 255], [200, 0, 0, 0]]])
    mask = load_stage_bitmap(save(tmp_path, "c.png", rgba, "RGBA"))
    # pure blue is occupied, pure red free (spec §9.1)
    assert mask.tolist() == [[True, False, True, False]]


def test_pgm_and_row_order_top_first(tmp_path: Path) -> None:
    grey = np.full((3, 2), 255)
    grey[0, 1] = 0
    path = tmp_path / "m.pgm"
    Image.fromarray(grey.astype(np.uint8)).save(path)
    mask = load_stage_bitmap(path)
    assert mask.shape == (3, 2) and mask[0, 1] and mask.sum() == 1


def test_occupied_bounding_box(tmp_path: Path) -> None:
    mask = np.zeros((6, 8), dtype=bool)
    mask[1, 2] = mask[4, 6] = True
    box = occupied_bounding_box(mask)
    assert tuple(box) == (1, 5, 2, 7)  # half-open: rows 1..4, cols 2..6
    assert occupied_bounding_box(np.zeros((3, 3), dtype=bool)) is None


def test_missing_bitmap_names_the_path_and_the_asking_line(tmp_path: Path) -> None:
    where = SourceLocation("w.world", 12, 5)
    missing = tmp_path / "nope.png"
    with pytest.raises(WorldError) as error:
        load_stage_bitmap(missing, where)
    assert str(error.value).startswith("w.world:12:5:")
    assert str(missing) in str(error.value)


def test_corrupt_image_is_a_world_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"not a png at all")
    with pytest.raises(WorldError, match=r"bad\.png"):
        load_stage_bitmap(bad)


def test_trimmed_white_margins_are_warned_about_with_the_resulting_scale(tmp_path: Path) -> None:
    from stage_sim.worldfile.loader import load_world_text

    image = np.full((10, 20), 255)
    image[2:8, 5:15] = 0  # occupied box 10 x 6 px inside a 20 x 10 image
    save(tmp_path, "margins.png", image)
    world = load_world_text('model( size [20 10 1] bitmap "margins.png" )\n', tmp_path / "w.world")
    (warning,) = [w for w in world.warnings if "margins.png" in w.message]
    assert "10x6 of 20x10" in warning.message and "2.00000 x 1.66667 m" in warning.message
    assert warning.location is not None and warning.location.line == 1
    full = np.full((10, 20), 255)
    full[0, 0] = full[-1, -1] = 0
    save(tmp_path, "full.png", full)
    world = load_world_text('model( size [20 10 1] bitmap "full.png" )\n', tmp_path / "w.world")
    assert not [w for w in world.warnings if "full.png" in w.message]


def test_palette_images_use_the_colour_shown_not_the_index(tmp_path: Path) -> None:
    image = Image.new("P", (3, 1))
    image.putpalette([255, 255, 255, 0, 0, 0, 0, 0, 255] + [0] * 759)  # index 0 white, 1 black, 2 blue
    image.putdata([0, 1, 2])
    image.save(tmp_path / "p.png")
    assert load_stage_bitmap(tmp_path / "p.png").tolist() == [[False, True, True]]


def test_grey_alpha_one_bit_and_sixteen_bit_images(tmp_path: Path) -> None:
    grey_alpha = np.array([[[0, 0], [255, 255], [127, 255], [128, 0]]])
    assert load_stage_bitmap(save(tmp_path, "la.png", grey_alpha, "LA")).tolist() == [[True, False, True, False]]
    Image.fromarray(np.array([[True, False]])).save(tmp_path / "bits.png")  # mode "1": True = white
    assert load_stage_bitmap(tmp_path / "bits.png").tolist() == [[False, True]]
    wide = Image.fromarray(np.array([[0, 32767, 32768, 65535]], dtype=np.uint16))
    wide.save(tmp_path / "wide.png")  # libpng's strip_16 keeps the high byte: 32767 -> 127
    assert load_stage_bitmap(tmp_path / "wide.png").tolist() == [[True, True, False, False]]


@pytest.mark.parametrize("suffix", [".jpg", ".gif", ".bmp", ".pnm", ".tif"])
def test_other_image_formats(tmp_path: Path, suffix: str) -> None:
    image = np.full((16, 32), 255)
    image[:, :16] = 0  # large blocks so lossy JPEG keeps the halves apart
    mask = load_stage_bitmap(save(tmp_path, "img" + suffix, image))
    assert mask[:, :14].all() and not mask[:, 18:].any()


def test_ascii_pgm_with_small_maxval(tmp_path: Path) -> None:
    path = tmp_path / "a.pgm"
    path.write_text("P2\n# comment\n3 1\n15\n0 7 15\n")  # 7/15 of white is 119: occupied
    assert load_stage_bitmap(path).tolist() == [[True, True, False]]


def test_a_directory_is_not_a_bitmap(tmp_path: Path) -> None:
    where = SourceLocation("w.world", 3, 1)
    with pytest.raises(WorldError) as error:
        load_stage_bitmap(tmp_path, where)
    assert error.value.location == where and str(tmp_path) in str(error.value)


def test_missing_bitmap_message_and_location(tmp_path: Path) -> None:
    where = SourceLocation("w.world", 7, 2)
    with pytest.raises(WorldError) as error:
        load_stage_bitmap(tmp_path / "x" / "gone.png", where)
    assert error.value.what == f"bitmap not found: {tmp_path / 'x' / 'gone.png'}"
    assert error.value.location == where


def test_truncated_image_is_a_world_error_naming_the_file(tmp_path: Path) -> None:
    good = save(tmp_path, "t.png", np.random.default_rng(0).integers(0, 256, (64, 64)))
    truncated = tmp_path / "truncated.png"
    truncated.write_bytes(good.read_bytes()[:200])
    with pytest.raises(WorldError, match=r"truncated\.png"):
        load_stage_bitmap(truncated)


def test_bounding_box_fields_and_full_image() -> None:
    mask = np.ones((4, 5), dtype=bool)
    box = occupied_bounding_box(mask)
    assert box is not None
    assert (box.row0, box.row1, box.col0, box.col1) == (0, 4, 0, 5)
    assert (box.height, box.width) == (4, 5)
    single = np.zeros((4, 5), dtype=bool)
    single[3, 4] = True
    assert occupied_bounding_box(single) == (3, 4, 4, 5)
