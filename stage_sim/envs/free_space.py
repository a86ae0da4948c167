"""Where a robot may start and where its goal may be: free space with room for the body, reachable.

A cell is a valid centre when the nearest cell that blocks the robots (their collision layer, the grid's
edge included) is farther than the robot's radius plus a margin, measured by an exact Euclidean distance
transform. Valid cells are grouped into 8-connected regions, so that a goal is always drawn in the region
of its start: a robot is never asked to reach a closed room. All draws come from the caller's generator.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from stage_sim.sim.simulation import Simulation

#: Candidates drawn per attempt when placing one robot; attempts stop after :data:`MAX_ATTEMPTS`.
BATCH = 64
MAX_ATTEMPTS = 50


class PlacementError(ValueError):
    """The world has no room for the requested robots, goals or separations."""


class FreeSpace:
    """The valid centres for the robots of ``sim`` (the largest of them, with ``margin`` to spare)."""

    def __init__(self, sim: Simulation, robots: list[int], margin: float) -> None:
        static = sim.static
        static.grid.check_dense("placing robots in free space (a distance transform of the whole world)")
        blocked = np.zeros(static.shape, dtype=bool)
        for band in {sim.robots[i].z_band for i in robots}:
            blocked |= static.collision_layer(*band)
        padded = np.pad(blocked, 1, constant_values=True)
        clearance = ndimage.distance_transform_edt(~padded)[1:-1, 1:-1] * static.resolution
        self.radius = max(sim.robots[i].radius for i in robots)
        valid = clearance > self.radius + margin + static.resolution
        self.regions, _ = ndimage.label(valid, structure=np.ones((3, 3), dtype=bool))
        self.cells = np.flatnonzero(valid)
        self.resolution = static.resolution
        self.origin = np.asarray(static.origin_xy, dtype=np.float64)
        self.width = static.shape[1]
        if self.cells.size == 0:
            raise PlacementError(f"no free space wide enough for a robot of radius {self.radius:.2f} m")

    def centres(self, cells: np.ndarray) -> np.ndarray:
        """World (x, y) of the centres of flat cell indices."""
        rows, cols = np.divmod(cells, self.width)
        return self.origin + (np.stack([cols, rows], axis=-1) + 0.5) * self.resolution

    def region_of(self, points: np.ndarray) -> np.ndarray:
        """Region label at world points (0: not a valid centre)."""
        cols, rows = np.floor((np.asarray(points) - self.origin) / self.resolution).astype(np.int64).T
        inside = (rows >= 0) & (rows < self.regions.shape[0]) & (cols >= 0) & (cols < self.width)
        labels = np.zeros(len(rows), dtype=self.regions.dtype)
        labels[inside] = self.regions[rows[inside], cols[inside]]
        return labels

    def draw(
        self, rng: np.random.Generator, avoid: np.ndarray, separation: float, region: int = 0,
        away_from: np.ndarray | None = None, min_distance: float = 0.0,
    ) -> np.ndarray:
        """One valid point at least ``separation`` from every row of ``avoid`` (M, 2), in ``region`` (0: any)
        and at least ``min_distance`` from ``away_from``."""
        pool = self.cells if region == 0 else self.cells[self.regions.ravel()[self.cells] == region]
        for _ in range(MAX_ATTEMPTS):
            points = self.centres(pool[rng.integers(len(pool), size=BATCH)])
            ok = np.ones(BATCH, dtype=bool)
            if len(avoid):
                ok &= np.min(np.linalg.norm(points[:, None] - avoid[None], axis=-1), axis=1) >= separation
            if away_from is not None:
                ok &= np.linalg.norm(points - away_from, axis=1) >= min_distance
            if ok.any():
                return points[np.argmax(ok)]
        raise PlacementError(
            f"could not place a robot {separation:.2f} m from the others"
            + (f" and {min_distance:.2f} m from its start" if away_from is not None else "")
            + f" after {MAX_ATTEMPTS * BATCH} tries: use fewer robots, a shorter goal distance or a larger world")

    def starts_and_goals(
        self, rng: np.random.Generator, count: int, fixed: np.ndarray, min_goal_distance: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """``count`` start poses (x, y, yaw) and goals (x, y), clear of each other and of ``fixed`` (M, 2)."""
        separation = 2 * self.radius + self.resolution
        starts = np.empty((count, 3))
        goals = np.empty((count, 2))
        for i in range(count):
            placed = np.concatenate([fixed.reshape(-1, 2), starts[:i, :2]])
            start = self.draw(rng, placed, separation)
            region = int(self.region_of(start[None])[0])
            goal = self.draw(rng, np.concatenate([fixed.reshape(-1, 2), goals[:i]]), separation, region,
                             start, min_goal_distance)
            starts[i] = (*start, rng.uniform(-np.pi, np.pi))
            goals[i] = goal
        return starts, goals
