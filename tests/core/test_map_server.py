"""map_server YAML maps: thresholds, negate, modes, alpha, row flip, origin and every error."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from stage_sim.core.errors import WorldError
from stage_sim.core.map_server import load_map_image, load_map_yaml

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
        ("image: m.png\nresolution: -1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
         "resolution"),
        ("image: gone.png\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
         "gone.png"),
        ("image: m.png\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n"
         "mode: fancy\n", "mode"),
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
