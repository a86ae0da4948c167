"""Bundled data: it is found from anywhere, and the drawn maps have the properties the worlds rely on."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stage_sim.worldfile.bitmap import load_stage_bitmap, occupied_bounding_box
from stage_sim.worldfile.bundled import bundled_worlds, data_root, find_world
from stage_sim.worldfile.errors import WorldError
from stage_sim.worldfile.loader import load_world
from stage_sim.worldfile.map_yaml import load_map_yaml

RES = 0.05
ROBOT_RADIUS = 0.25  # half the diagonal of the 0.4 x 0.3 m course robot

MAPS = {"rooms": (541, 433), "corridor": (320, 200), "office_1200x1100": (1200, 1100)}

# One point inside each room of maps/rooms.png (metres, origin at the lower-left image corner).
ROOMS = {
    "corridor": (11.1, 9.2),
    "A1": (4.5, 13.0),
    "A2": (3.0, 18.5),
    "B": (9.3, 12.5),
    "C": (15.0, 16.0),
    "D": (20.0, 14.0),
    "E": (2.5, 4.0),
    "F": (7.5, 4.5),
    "G": (13.0, 2.0),
    "H": (19.0, 6.5),
    "lobby": (24.5, 18.0),
}
CORRIDOR_ROOMS = {
    "start": (1.5, 5.0),
    "south 1": (1.6, 2.5),
    "south 2": (4.6, 2.5),
    "south 3": (7.7, 2.5),
    "south 4": (10.0, 3.2),
    "south 5": (14.0, 2.5),
    "north-west": (2.0, 7.5),
    "middle west": (10.3, 7.0),
    "middle east": (14.0, 7.0),
    "upper corridor end": (15.3, 9.3),
}


def mask_of(name: str) -> np.ndarray:
    return load_stage_bitmap(data_root() / "maps" / f"{name}.png")


def clearance(mask: np.ndarray, x: float, y: float) -> float:
    """Distance from (x, y) to the nearest occupied pixel square (row 0 = top, origin bottom-left)."""
    rows, cols = np.nonzero(mask)
    x0, x1 = cols * RES, (cols + 1) * RES
    y1 = (mask.shape[0] - rows) * RES
    y0 = y1 - RES
    dx = np.maximum(np.maximum(x0 - x, x - x1), 0.0)
    dy = np.maximum(np.maximum(y0 - y, y - y1), 0.0)
    return float(np.sqrt(dx * dx + dy * dy).min())


def reachable(mask: np.ndarray, start: tuple[float, float], radius: float) -> np.ndarray:
    """Pixels a disc of ``radius`` can reach from ``start`` (4-connected flood fill of the free C-space)."""
    r = int(np.ceil(radius / RES))
    padded = np.pad(mask, r, constant_values=True)
    blocked = np.zeros_like(mask)
    h, w = mask.shape
    for dr in range(-r, r + 1):
        for dc in range(-r, r + 1):
            if max(abs(dr) - 0.5, 0) ** 2 + max(abs(dc) - 0.5, 0) ** 2 < (radius / RES) ** 2:
                blocked |= padded[r + dr : r + dr + h, r + dc : r + dc + w]
    free = ~blocked
    seen = np.zeros_like(mask)
    seen[h - 1 - int(start[1] / RES), int(start[0] / RES)] = True
    assert free[seen].all(), "start is not free"
    while True:
        grown = seen.copy()
        grown[1:] |= seen[:-1]
        grown[:-1] |= seen[1:]
        grown[:, 1:] |= seen[:, :-1]
        grown[:, :-1] |= seen[:, 1:]
        grown &= free
        if (grown == seen).all():
            return seen
        seen = grown


def at(mask: np.ndarray, x: float, y: float) -> bool:
    return bool(mask[mask.shape[0] - 1 - int(y / RES), int(x / RES)])


def test_data_root_holds_the_bundled_folders() -> None:
    root = data_root()
    assert all((root / folder).is_dir() for folder in ("worlds", "maps", "robots"))


def test_bundled_world_names() -> None:
    names = bundled_worlds()
    assert {"rooms.world", "multi_robots.world", "omni.world", "rooms_yaml.world", "corridor.world"} <= set(names)
    assert names == sorted(names)


def test_find_world_by_name_or_stem_from_another_directory(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert find_world("rooms.world") == data_root() / "worlds" / "rooms.world"
    assert find_world("corridor") == data_root() / "worlds" / "corridor.world"
    assert find_world("rooms.world").is_file()


def test_find_world_prefers_an_existing_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "rooms.world").write_text("# mine\n")
    assert find_world("rooms.world") == Path("rooms.world")
    assert find_world(tmp_path / "rooms.world") == tmp_path / "rooms.world"


def test_find_world_unknown_lists_the_bundled_worlds(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(FileNotFoundError, match=r"nowhere\.world.*rooms\.world"):
        find_world("nowhere.world")
    with pytest.raises(FileNotFoundError):
        find_world("some/dir/rooms.world")  # a path with folders is never a bundled name


def test_load_world_finds_a_bundled_world_by_name(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    for name in ("rooms.world", "rooms"):
        description = load_world(name)
        assert description.path == data_root() / "worlds" / "rooms.world"
        assert description.robots()


def test_load_world_prefers_a_file_of_that_name(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "rooms.world").write_text('position( name "mine" )\n')
    assert [robot.name for robot in load_world("rooms.world").robots()] == ["mine"]


def test_load_world_of_nothing_says_what_it_tried(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(WorldError, match=r"nowhere\.world \(no such file, nor a bundled world of that name; "
                       r"bundled worlds: .*rooms\.world"):
        load_world("nowhere.world")
    with pytest.raises(FileNotFoundError, match=r"some/dir/rooms\.world \(no such file; bundled worlds"):
        load_world("some/dir/rooms.world")


@pytest.mark.parametrize("name", sorted(MAPS))
def test_maps_have_the_documented_size_and_an_outer_wall(name: str) -> None:
    mask = mask_of(name)
    assert mask.shape[::-1] == MAPS[name]
    assert occupied_bounding_box(mask) == (0, mask.shape[0], 0, mask.shape[1])  # Stage maps it exactly
    grid = load_map_yaml(data_root() / "maps" / f"{name}.yaml")
    assert (grid.width, grid.height, grid.resolution, grid.origin) == (*MAPS[name], RES, (0.0, 0.0, 0.0))
    assert np.array_equal(grid.occupied_image_rows(), mask)  # pure black and white: both readings agree


def test_rooms_start_pose_is_free_with_room_to_turn() -> None:
    assert clearance(mask_of("rooms"), 11.1, 9.2) >= 0.6


def test_every_room_is_reachable_through_doors_at_least_one_metre_wide() -> None:
    mask = mask_of("rooms")
    assert len(ROOMS) >= 7  # a corridor, six rooms or more
    wide = reachable(mask, ROOMS["corridor"], radius=0.5)  # a 1.0 m disc passes every door
    assert [name for name, (x, y) in ROOMS.items() if not at(wide, x, y)] == []


def test_corridor_map_is_passable_for_the_robot_but_narrow() -> None:
    mask = mask_of("corridor")
    assert clearance(mask, *CORRIDOR_ROOMS["start"]) >= 0.45
    small = reachable(mask, CORRIDOR_ROOMS["start"], radius=0.2)  # the robot's half length fits a 0.45 m door
    assert [name for name, (x, y) in CORRIDOR_ROOMS.items() if not at(small, x, y)] == []
    wide = reachable(mask, CORRIDOR_ROOMS["start"], radius=ROBOT_RADIUS)  # turning in place does not fit
    assert not at(wide, *CORRIDOR_ROOMS["south 1"])


def test_office_map_is_one_connected_floor() -> None:
    mask = mask_of("office_1200x1100")
    free = reachable(mask, (15.0, 13.75), radius=ROBOT_RADIUS)  # a corridor crossing
    roomy = ~mask
    assert free.sum() > 0.8 * roomy.sum()
