#!/usr/bin/env python3
"""Draw the bundled floor plans (maps/*.png and their map_server YAML files) deterministically.

The maps are the project's own drawings (the course's rooms.png is not redistributable). Layouts are
written in metres with y up, at 0.05 m per pixel; walls are black (0), free space white (255). Every map
has an outer wall, so its occupied pixels touch all four image borders and Stage's stretch-to-size of
the occupied bounding box maps it exactly (spec §9.1).

Run from anywhere: ``python tools/draw_maps.py`` (writes into the repository's ``maps/`` folder).
"""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np
from PIL import Image

RESOLUTION = 0.05
WALL = 0.15
OUTER_WALL = 0.25
DOOR = 1.1
MAPS_DIR = Path(__file__).resolve().parent.parent / "maps"


class Floor:
    """An occupancy drawing in metres (y up) over an image whose row 0 is the top."""

    def __init__(self, width_m: float, height_m: float) -> None:
        self.width = _px(width_m)
        self.height = _px(height_m)
        self.occupied = np.zeros((self.height, self.width), dtype=bool)

    def box(self, x0: float, y0: float, x1: float, y1: float, occupied: bool = True) -> None:
        """Fill the rectangle [x0, x1] × [y0, y1] (metres) with wall or free space."""
        rows = slice(self.height - _px(y1), self.height - _px(y0))
        self.occupied[rows, _px(x0) : _px(x1)] = occupied

    def disk(self, cx: float, cy: float, radius: float) -> None:
        """A round obstacle (table, plant, pillar): pixels whose centre lies within ``radius``."""
        cols = (np.arange(self.width) + 0.5) * RESOLUTION
        ys = (self.height - np.arange(self.height) - 0.5) * RESOLUTION
        inside = (cols[np.newaxis, :] - cx) ** 2 + (ys[:, np.newaxis] - cy) ** 2 <= radius**2
        self.occupied |= inside

    def hwall(self, y: float, x0: float, x1: float, thickness: float = WALL) -> None:
        """A horizontal wall whose lower face is at ``y``."""
        self.box(x0, y, x1, y + thickness)

    def vwall(self, x: float, y0: float, y1: float, thickness: float = WALL) -> None:
        """A vertical wall whose left face is at ``x``."""
        self.box(x, y0, x + thickness, y1)

    def hdoor(self, y: float, x0: float, width: float = DOOR, thickness: float = WALL) -> None:
        """Open a doorway from ``x0`` to ``x0 + width`` in the horizontal wall at ``y``."""
        self.box(x0, y, x0 + width, y + thickness, occupied=False)

    def vdoor(self, x: float, y0: float, width: float = DOOR, thickness: float = WALL) -> None:
        """Open a doorway from ``y0`` to ``y0 + width`` in the vertical wall at ``x``."""
        self.box(x, y0, x + thickness, y0 + width, occupied=False)

    def outer_wall(self, thickness: float = OUTER_WALL) -> None:
        """Walls along all four image borders."""
        w, h = self.width * RESOLUTION, self.height * RESOLUTION
        self.box(0, 0, w, thickness)
        self.box(0, h - thickness, w, h)
        self.box(0, 0, thickness, h)
        self.box(w - thickness, 0, w, h)

    def save(self, name: str, with_yaml: bool = True) -> Path:
        """Write ``maps/<name>.png`` (8-bit grey) and, unless told not to, ``maps/<name>.yaml``."""
        MAPS_DIR.mkdir(exist_ok=True)
        png = MAPS_DIR / f"{name}.png"
        Image.fromarray(np.where(self.occupied, 0, 255).astype(np.uint8), mode="L").save(png, optimize=True)
        if with_yaml:
            (MAPS_DIR / f"{name}.yaml").write_text(
                "# Drawn by tools/draw_maps.py; origin = lower-left corner of the image.\n"
                f"image: {png.name}\n"
                f"resolution: {RESOLUTION}\n"
                "origin: [0.0, 0.0, 0.0]\n"
                "negate: 0\n"
                "occupied_thresh: 0.65\n"
                "free_thresh: 0.196\n"
                "mode: trinary\n"
            )
        return png


def _px(metres: float) -> int:
    """Metres to a pixel boundary index (layouts use multiples of 0.05 m)."""
    return round(metres / RESOLUTION)


def draw_rooms() -> Floor:
    """The office floor of worlds/rooms.world: 27.05 × 21.65 m, ten rooms around a 2 m corridor.

    The corridor runs along y 8.2..10.2 into an east lobby; the robot starts in it at (11.1, 9.2).
    North: A1, A2 (stacked), B, C, D. South: E, F, G, H. East: the lobby. Doors are 1.1 m wide.
    """
    floor = Floor(27.05, 21.65)
    floor.outer_wall()
    # Corridor walls and the lobby's west wall.
    floor.hwall(8.05, 0.25, 22.15)
    floor.hwall(10.2, 0.25, 22.15)
    floor.vwall(22.0, 0.25, 21.4)
    floor.box(22.0, 8.2, 22.15, 10.2, occupied=False)
    # North rooms: partitions, the A1/A2 split and the corridor doors.
    for x in (6.0, 12.5, 18.0):
        floor.vwall(x, 10.35, 21.4)
    floor.hwall(15.5, 0.25, 6.0)
    floor.hdoor(15.5, 2.5)
    for x in (3.0, 8.5, 14.0, 19.5):
        floor.hdoor(10.2, x)
    floor.vdoor(6.0, 17.5)  # A2 - B
    floor.vdoor(22.0, 16.0)  # D - lobby
    # South rooms.
    for x in (5.0, 10.0, 16.0):
        floor.vwall(x, 0.25, 8.05)
    for x in (2.0, 7.0, 12.5, 18.0):
        floor.hdoor(8.05, x)
    floor.vdoor(10.0, 3.0)  # F - G
    floor.vdoor(22.0, 4.0)  # H - lobby
    # Furniture: tables, desks, shelves, a round table, pillars and a reception desk.
    floor.box(0.25, 20.5, 4.0, 21.4)
    floor.box(1.0, 12.0, 3.0, 13.2)
    floor.box(8.0, 14.0, 11.0, 15.2)
    floor.box(12.65, 19.0, 14.5, 21.4)
    floor.box(16.5, 12.5, 18.0, 14.0)
    floor.disk(21.0, 20.5, 0.3)
    floor.box(0.25, 5.5, 1.2, 7.5)
    floor.box(6.0, 1.0, 9.0, 2.0)
    floor.box(12.0, 3.5, 14.0, 5.0)
    floor.disk(19.0, 4.0, 0.6)
    floor.box(24.25, 3.75, 24.75, 4.25)
    floor.box(24.25, 15.25, 24.75, 15.75)
    floor.box(24.0, 11.5, 25.8, 12.1)
    return floor


def draw_corridor() -> Floor:
    """A 16 × 10 m floor of 1.0 m corridors and 0.45 m doors (1.5 widths of a 0.3 m wide robot).

    The main corridor runs along y 4.5..5.5; the robot starts at (1.5, 5.0). A 1.0 m corridor branches
    north at x 7.5..8.5 and turns east along y 8.8..9.8. Rooms open on the corridors through 0.45 m
    doors; neighbouring south rooms share 0.5 m doors.
    """
    floor = Floor(16.0, 10.0)
    floor.outer_wall(0.2)
    floor.hwall(4.35, 0.2, 15.8)
    floor.hwall(5.5, 0.2, 7.5)
    floor.hwall(5.5, 8.5, 15.8)
    # The north branch: walls either side, then the east turn under the outer wall.
    floor.vwall(7.35, 5.5, 9.8)
    floor.vwall(8.5, 5.5, 8.8)
    floor.hwall(8.65, 8.5, 15.8)
    # South rooms, 3.1 m wide, each with a 0.45 m door onto the corridor.
    for x in (3.0, 6.1, 9.2, 12.3):
        floor.vwall(x, 0.2, 4.35)
    for x in (1.3, 4.3, 7.4, 10.5, 13.8):
        floor.hdoor(4.35, x, 0.45)
    for x in (3.0, 9.2):
        floor.vdoor(x, 1.5, 0.5)
    # North-west room (west of the branch) and the rooms between the main corridor and the turn.
    floor.hdoor(5.5, 3.5, 0.45)
    floor.vwall(12.0, 5.65, 8.65)
    for x in (10.0, 13.5):
        floor.hdoor(5.5, x, 0.45)
        floor.hdoor(8.65, x + 0.5, 0.45)
    # A few obstacles inside rooms.
    floor.box(0.2, 0.2, 1.0, 1.2)
    floor.disk(11.0, 2.0, 0.4)
    floor.box(4.5, 7.5, 6.5, 8.3)
    return floor


def draw_office(width_px: int = 1200, height_px: int = 1100, seed: int = 7) -> Floor:
    """A large generated office (60 × 55 m by default) for benchmarks: a grid of 2 m corridors with rows
    of rooms of random widths on both sides, one door each, and some furniture. Same seed, same map.
    """
    rng = random.Random(seed)
    floor = Floor(width_px * RESOLUTION, height_px * RESOLUTION)
    w, h = width_px * RESOLUTION, height_px * RESOLUTION
    floor.outer_wall(0.3)
    corridor_ys = [round(h * k / 4 / RESOLUTION) * RESOLUTION for k in (1, 2, 3)]
    corridor_xs = [round(w * k / 4 / RESOLUTION) * RESOLUTION for k in (1, 2, 3)]
    # Free extents between corridors (and the outer wall), as (start, end) pairs.
    edges_y = [0.3] + [y for c in corridor_ys for y in (c - 1.0 - WALL, c + 1.0 + WALL)] + [h - 0.3]
    edges_x = [0.3] + [x for c in corridor_xs for x in (c - 1.0 - WALL, c + 1.0 + WALL)] + [w - 0.3]
    for c in corridor_ys:
        floor.hwall(c - 1.0 - WALL, 0.3, w - 0.3)
        floor.hwall(c + 1.0, 0.3, w - 0.3)
    for c in corridor_xs:
        floor.vwall(c - 1.0 - WALL, 0.3, h - 0.3)
        floor.vwall(c + 1.0, 0.3, h - 0.3)
    for c in corridor_ys:  # reopen the crossings
        for x in corridor_xs:
            floor.box(x - 1.0 - WALL, c - 1.0 - WALL, x + 1.0 + WALL, c + 1.0 + WALL, occupied=False)
    for band in range(0, len(edges_y), 2):
        y0, y1 = edges_y[band], edges_y[band + 1]
        for column in range(0, len(edges_x), 2):
            x0, x1 = edges_x[column], edges_x[column + 1]
            if band == 0:
                _room_row(floor, rng, x0, x1, y0, y1, corridor_above=True)
            elif band == len(edges_y) - 2:
                _room_row(floor, rng, x0, x1, y0, y1, corridor_above=False)
            else:  # rooms back to back, facing the corridors below and above
                split = round((y0 + y1) / 2 / RESOLUTION) * RESOLUTION
                floor.hwall(split, x0, x1)
                _room_row(floor, rng, x0, x1, y0, split, corridor_above=False)
                _room_row(floor, rng, x0, x1, split + WALL, y1, corridor_above=True)
    return floor


def _room_row(
    floor: Floor, rng: random.Random, x0: float, x1: float, y0: float, y1: float, corridor_above: bool
) -> None:
    """Split [x0, x1] × [y0, y1] into rooms 3..6 m wide, each with a door onto the corridor side."""
    door_wall_y = y1 if corridor_above else y0 - WALL
    x = x0
    while x < x1 - 1e-6:
        width = rng.choice((3.5, 4.0, 4.5, 5.0, 6.0))
        if x1 - (x + width + WALL) < 3.0:
            width = x1 - x
        else:
            floor.vwall(x + width, y0, y1)
        door_x = x + 0.5 + rng.randrange(round((width - 2.0) / RESOLUTION)) * RESOLUTION
        floor.hdoor(door_wall_y, door_x)
        if rng.random() < 0.6:  # a desk against the back wall, away from the door
            desk_y = y0 + 0.5 if corridor_above else y1 - 1.3
            floor.box(x + 0.6, desk_y, x + 0.6 + rng.choice((1.2, 1.6, 2.0)), desk_y + 0.8)
        x += width + WALL


def main() -> None:
    """Draw every bundled map and report the facts the worlds rely on."""
    for name, floor, with_yaml in (
        ("rooms", draw_rooms(), True),
        ("corridor", draw_corridor(), True),
        ("office_1200x1100", draw_office(), True),
    ):
        png = floor.save(name, with_yaml)
        print(f"{png.relative_to(MAPS_DIR.parent)}: {floor.width}x{floor.height} px, {png.stat().st_size} bytes")


if __name__ == "__main__":
    main()
