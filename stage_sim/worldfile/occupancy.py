"""A map_server-style occupancy grid: cell values, cell size and where cell (0, 0) sits in the world."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

OCCUPIED = 100
FREE = 0
UNKNOWN = -1
RAW_UNKNOWN = 255


@dataclass(frozen=True)
class OccupancyGrid:
    """Cells in nav_msgs/OccupancyGrid convention.

    ``values[row, col]`` is int8: 100 occupied, 0 free, -1 unknown (or 1..99 / 0..255 in map_server's
    scale and raw modes). Row 0 is the *bottom* row (smallest y), unlike image rows. ``origin`` is the
    pose (x, y, yaw) of the lower-left corner of cell (0, 0), as in a map_server YAML file. ``mode`` is
    the map_server mode the values came from ("trinary", "scale" or "raw"); it decides what blocks.
    """

    values: np.ndarray
    resolution: float
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mode: str = "trinary"

    @property
    def width(self) -> int:
        """Number of columns (cells along x)."""
        return int(self.values.shape[1])

    @property
    def height(self) -> int:
        """Number of rows (cells along y)."""
        return int(self.values.shape[0])

    @property
    def occupied(self) -> np.ndarray:
        """Boolean mask of cells that block motion and rays (row 0 = bottom).

        Trinary and scale maps block at 100. Raw maps hold bytes 0..255 wrapped into int8; like the nav2
        static costmap they block at 100..254 (255 is "unknown").
        """
        if self.mode == "raw":
            raw = self.values.view(np.uint8)
            return (raw >= OCCUPIED) & (raw < RAW_UNKNOWN)
        return self.values >= OCCUPIED

    def occupied_image_rows(self) -> np.ndarray:
        """:attr:`occupied` with row 0 = top, the row order of images and of ``Bitmap.occupied``."""
        return np.flipud(self.occupied)

    @property
    def extent(self) -> tuple[float, float]:
        """Width and height of the whole grid in metres."""
        return self.width * self.resolution, self.height * self.resolution
