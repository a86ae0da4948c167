"""map_server YAML maps: thresholds, negate, modes, alpha, row flip, origin and every error."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from stage_sim.worldfile.errors import WorldError
from stage_sim.worldfile.map_yaml import load_map_image, load_map_yaml

YAML = """image: {image}
resolution: 0.05
origin: [-1.0, 2.0, 0.0]
negate: {negate}
occupied_thresh: 0.65
free_thresh: 0.196
{extra}"""


def write_map(tmp_path: Path, pixels: np.ndarray, negate: int = 0, extra: str = "", mode: str | None = None) -> Path:
    Image.fromarray(pixels.astype(np.uint8), mode=mode).save(tmp_path / "m.png")
    path = tmp_path / "m.yaml"
    path.write_text(YAML.format(image="m.png", negate=negate, extra=extra))
    return path


def test_trinary_thresholds_with_the_usual_values(tmp_path: Path) -> None:
    # 0.65/0.196: grey <= 89 occupied, >= 206 free, 90..205 unknown (spec §9.2)
    grid = load_map_yaml(write_map(tmp_path, np.array([[0, 89, 90, 205, 206, 255]])))
    assert grid.values.tolist() == [[100, 100, -1, -1, 0, 0]]
    assert grid.occupied.tolist() == [[True, True, False, False, False, False]]
    assert grid.resolution == 0.05 and grid.origin == (-1.0, 2.0, 0.0)


def test_rows_are_flipped_so_row_zero_is_the_bottom(tmp_path: Path) -> None:
    pixels = np.full((3, 2), 255)
    pixels[0, 0] = 0  # top-left pixel of the image
    grid = load_map_yaml(write_map(tmp_path, pixels))
    assert grid.values[2, 0] == 100 and grid.values[0, 0] == 0


def test_negate_inverts_the_meaning(tmp_path: Path) -> None:
    grid = load_map_yaml(write_map(tmp_path, np.array([[0, 255]]), negate=1))
    assert grid.values.tolist() == [[0, 100]]


def test_threshold_exactly_at_the_boundary_is_unknown(tmp_path: Path) -> None:
    # p = (255 - x)/255 equals occupied_thresh 0.6 exactly for x = 102: comparisons are strict
    path = write_map(tmp_path, np.array([[102, 153]]), extra="")
    path.write_text(path.read_text().replace("0.65", "0.6").replace("0.196", "0.4"))
    grid = load_map_yaml(path)
    assert grid.values.tolist() == [[-1, -1]]


def test_scale_mode_interpolates_and_alpha_zero_is_unknown(tmp_path: Path) -> None:
    rgba = np.array([[[150, 150, 150, 255], [150, 150, 150, 0], [0, 0, 0, 255]]])
    grid = load_map_yaml(write_map(tmp_path, rgba, extra="mode: scale\n", mode="RGBA"))
    p = (255 - 150) / 255
    assert grid.values[0, 0] == int(1 + 98 * (p - 0.196) / (0.65 - 0.196))
    assert grid.values[0, 1] == -1
    assert grid.values[0, 2] == 100


def test_raw_mode_keeps_the_grey_value(tmp_path: Path) -> None:
    grid = load_map_yaml(write_map(tmp_path, np.array([[0, 100, 254, 255]]), extra="mode: raw\n"))
    assert grid.values.view(np.uint8).tolist() == [[0, 100, 254, 255]]
    assert grid.occupied.tolist() == [[False, True, True, False]]


def test_deprecated_image_form_defaults(tmp_path: Path) -> None:
    Image.fromarray(np.array([[0, 255]], dtype=np.uint8)).save(tmp_path / "x.pgm")
    grid = load_map_image(tmp_path / "x.pgm", 0.1)
    assert grid.values.tolist() == [[100, 0]] and grid.origin == (0.0, 0.0, 0.0)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("image: m.png\nresolution: [oops\n", "m.yaml:"),
        ("resolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n", "image"),
        (
            "image: m.png\nresolution: -1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
            "resolution",
        ),
        (
            "image: gone.png\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.2\n",
            "gone.png",
        ),
        (
            "image: m.png\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n"
            "mode: fancy\n",
            "mode",
        ),
    ],
    ids=["bad-yaml", "missing-image-key", "bad-resolution", "missing-image-file", "bad-mode"],
)
def test_errors_name_the_file_and_what_is_wrong(tmp_path: Path, text: str, fragment: str) -> None:
    Image.fromarray(np.zeros((2, 2), dtype=np.uint8)).save(tmp_path / "m.png")
    path = tmp_path / "m.yaml"
    path.write_text(text)
    with pytest.raises(WorldError) as error:
        load_map_yaml(path)
    assert fragment in str(error.value)
    assert "m.yaml" in str(error.value) or "gone.png" in str(error.value)


def test_bundled_rooms_map_has_the_documented_size() -> None:
    grid = load_map_yaml(Path(__file__).resolve().parents[2] / "maps" / "rooms.yaml")
    assert (grid.width, grid.height) == (541, 433)
    occupied = grid.occupied
    assert occupied[0].any() and occupied[-1].any() and occupied[:, 0].any() and occupied[:, -1].any()


FULL = "image: {image}\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: {occ}\nfree_thresh: {free}\n"


def write_yaml(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "m.yaml"
    path.write_text(text)
    return path


def test_thresholds_equal_to_p_exactly_give_unknown_and_one_grey_level_more_decides(tmp_path: Path) -> None:
    Image.fromarray(np.array([[99, 100, 200, 201]], dtype=np.uint8)).save(tmp_path / "m.png")
    occ, free = (255 - 100) / 255, (255 - 200) / 255  # repr round-trips the exact doubles
    grid = load_map_yaml(write_yaml(tmp_path, FULL.format(image="m.png", occ=repr(occ), free=repr(free))))
    assert grid.values.tolist() == [[100, -1, -1, 0]]


def test_colour_pixels_use_the_channel_mean(tmp_path: Path) -> None:
    rgb = np.array([[[255, 0, 0], [0, 255, 255], [255, 255, 0], [30, 60, 90]]])
    # means 85 (occupied), 170 (unknown), 170 (unknown), 60 (occupied)
    grid = load_map_yaml(write_map(tmp_path, rgb, mode="RGB"))
    assert grid.values.tolist() == [[100, -1, -1, 100]]


def test_trinary_mode_averages_alpha_in(tmp_path: Path) -> None:
    rgba = np.array([[[255, 255, 255, 0], [255, 255, 255, 255], [0, 0, 0, 0], [0, 0, 0, 255]]])
    grid = load_map_yaml(write_map(tmp_path, rgba, mode="RGBA"))
    # means 191.25 (unknown), 255 (free), 0 (occupied), 63.75 (occupied)
    assert grid.values.tolist() == [[-1, 0, 100, 100]]


def test_grey_alpha_counts_as_rgba(tmp_path: Path) -> None:
    grey_alpha = np.array([[[0, 255], [255, 0]]])
    grid = load_map_yaml(write_map(tmp_path, grey_alpha, mode="LA"))
    # (g, g, g, a) means: 63.75 occupied; 191.25 unknown (a plain (g, a) mean would give 127.5 for both)
    assert grid.values.tolist() == [[100, -1]]


def test_scale_mode_values_by_hand(tmp_path: Path) -> None:
    grey = np.array([[150, 206, 89, 90, 205]])
    grid = load_map_yaml(write_map(tmp_path, grey, extra="mode: scale\n"))
    # 150: p = 0.41176, ratio = 0.47525 -> 1 + 46.57 -> 47; 90: ratio 0.99 -> 98; 205: ratio ~0.0002 -> 1
    assert grid.values.tolist() == [[47, 0, 100, 98, 1]]
    assert grid.mode == "scale" and grid.occupied.tolist() == [[False, False, True, False, False]]


def test_scale_mode_excludes_alpha_from_the_mean(tmp_path: Path) -> None:
    rgba = np.array([[[255, 255, 255, 0], [0, 0, 0, 0], [150, 150, 150, 10]]])
    grid = load_map_yaml(write_map(tmp_path, rgba, extra="mode: scale\n", mode="RGBA"))
    assert grid.values.tolist() == [[0, 100, 47]]


def test_raw_mode_with_negate_and_alpha(tmp_path: Path) -> None:
    rgba = np.array([[[200, 200, 200, 0], [55, 55, 55, 255]]])
    grid = load_map_yaml(write_map(tmp_path, rgba, negate=1, extra="mode: raw\n", mode="RGBA"))
    assert grid.values.view(np.uint8).tolist() == [[55, 200]]
    assert grid.values.dtype == np.int8 and grid.values.tolist() == [[55, -56]]


def test_origin_resolution_and_image_paths(tmp_path: Path) -> None:
    (tmp_path / "img").mkdir()
    Image.fromarray(np.zeros((3, 4), dtype=np.uint8)).save(tmp_path / "img" / "floor.png")
    text = "image: img/floor.png\nresolution: 0.1\norigin: [1.5, -2, 0.3]\nnegate: 0\n"
    text += "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    grid = load_map_yaml(write_yaml(tmp_path, text))
    assert (grid.width, grid.height, grid.resolution, grid.origin) == (4, 3, 0.1, (1.5, -2.0, 0.3))
    assert grid.extent == pytest.approx((0.4, 0.3))
    absolute = text.replace("img/floor.png", str(tmp_path / "img" / "floor.png"))
    (tmp_path / "elsewhere").mkdir()
    assert load_map_yaml(write_yaml(tmp_path / "elsewhere", absolute)).width == 4


def test_numeric_strings_are_read_like_yaml_cpp(tmp_path: Path) -> None:
    Image.fromarray(np.zeros((1, 1), dtype=np.uint8)).save(tmp_path / "m.png")
    text = FULL.format(image="m.png", occ="0.65", free="0.196").replace("0.05", "5e-2")
    assert load_map_yaml(write_yaml(tmp_path, text)).resolution == 0.05


def test_yaml_syntax_error_points_at_line_and_column(tmp_path: Path) -> None:
    path = write_yaml(tmp_path, "image: m.png\nresolution: 0.05\norigin: [0, 0, 0\nnegate: 0\n")
    with pytest.raises(WorldError) as error:
        load_map_yaml(path)
    location = error.value.location
    assert location is not None and location.file == str(path) and location.line >= 3 and location.column >= 1


def test_missing_keys_are_all_listed(tmp_path: Path) -> None:
    with pytest.raises(WorldError) as error:
        load_map_yaml(write_yaml(tmp_path, "image: m.png\nresolution: 0.05\n"))
    for key in ("origin", "negate", "occupied_thresh", "free_thresh"):
        assert key in str(error.value)


@pytest.mark.parametrize(
    ("key", "value", "line"),
    [
        ("origin", "[1, 2]", 3),
        ("origin", "here", 3),
        ("origin", "[0, x, 0]", 3),
        ("resolution", "fine", 2),
        ("resolution", ".nan", 2),
        ("resolution", "0", 2),
        ("negate", "2", 4),
        ("negate", "maybe", 4),
        ("occupied_thresh", "1.5", 5),
        ("occupied_thresh", "true", 5),
        ("free_thresh", "0.7", 6),
        ("image", "[a, b]", 1),
        ("image", "''", 1),
    ],
)
def test_bad_values_point_at_their_line(tmp_path: Path, key: str, value: str, line: int) -> None:
    Image.fromarray(np.zeros((1, 1), dtype=np.uint8)).save(tmp_path / "m.png")
    lines = FULL.format(image="m.png", occ="0.65", free="0.196").splitlines()
    index = next(i for i, text in enumerate(lines) if text.startswith(key + ":"))
    lines[index] = f"{key}: {value}"
    path = write_yaml(tmp_path, "\n".join(lines) + "\n")
    with pytest.raises(WorldError) as error:
        load_map_yaml(path)
    assert key in str(error.value) or key in (error.value.expected or "")
    assert error.value.location is not None
    assert (error.value.location.file, error.value.location.line) == (str(path), line)


def test_not_a_mapping(tmp_path: Path) -> None:
    for text in ("", "- a\n- b\n", "just text\n"):
        with pytest.raises(WorldError, match="mapping"):
            load_map_yaml(write_yaml(tmp_path, text))


def test_missing_yaml_is_reported_where_it_was_asked_for(tmp_path: Path) -> None:
    from stage_sim.worldfile.errors import SourceLocation

    where = SourceLocation("w.world", 9, 3)
    with pytest.raises(WorldError) as error:
        load_map_yaml(tmp_path / "none.yaml", where)
    assert error.value.location == where and str(tmp_path / "none.yaml") in str(error.value)


def test_missing_image_names_the_tried_path_at_the_image_line(tmp_path: Path) -> None:
    path = write_yaml(
        tmp_path,
        "resolution: 0.05\nimage: maps/gone.png\norigin: [0, 0, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    with pytest.raises(WorldError) as error:
        load_map_yaml(path)
    assert error.value.what == f"map image not found: {tmp_path / 'maps' / 'gone.png'}"
    assert error.value.location is not None and error.value.location.line == 2


def test_corrupt_image_names_the_image(tmp_path: Path) -> None:
    (tmp_path / "m.png").write_bytes(b"\x89PNG garbage")
    with pytest.raises(WorldError, match=r"m\.png"):
        load_map_yaml(write_yaml(tmp_path, FULL.format(image="m.png", occ="0.65", free="0.196")))


def test_deprecated_form_validates_its_parameters(tmp_path: Path) -> None:
    Image.fromarray(np.zeros((1, 1), dtype=np.uint8)).save(tmp_path / "x.png")
    with pytest.raises(WorldError, match="resolution"):
        load_map_image(tmp_path / "x.png", 0.0)
    with pytest.raises(WorldError, match="mode"):
        load_map_image(tmp_path / "x.png", 0.05, mode="binary")
    with pytest.raises(WorldError, match="map image not found"):
        load_map_image(tmp_path / "y.png", 0.05)
