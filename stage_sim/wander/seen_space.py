"""What a robot's laser has shown it of the world: a fine occupancy grid in the odometry frame, and the
shortest route through known free space to the nearest place that is still wanted (not yet visited).

The reactive wanderer only weighs new space it can see; once everything in view has been visited it would
tour at random and could leave far rooms, glimpsed once through a door, unvisited for a long time. This map
remembers the free space it has seen, so that the wanderer can head back towards it. Each scan lowers the
score of the cells its beams cross and raises that of the cells they end in (clipped, so that later scans
override what odometry drift has misplaced); a cell is free when its score is below zero. Routes are
breadth-first over 4-connected free cells, so they never cut through a cell that was seen occupied.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from stage_sim.wander import kernels
from stage_sim.wander.laser_reading import wrap

HIT, PASS, CLIP = 3, -1, 6  # score a cell gains when a beam ends in it, loses when one crosses it; bound
SAMPLE_STEP = 0.1  # m between the points along a beam that mark cells free
WANTED_BLOCK = 5  # cells: a place is wanted if enough wanted cells lie in the block of this side around it
WANTED_SHARE = 0.3  # share of that block that must be wanted (stray cells are not worth a trip)


class SeenSpace:
    """Free and occupied cells seen by the laser in a fixed square of ``extent`` m centred on the origin."""

    def __init__(self, cell: float = 0.1, extent: float = 120.0) -> None:
        self.cell = cell
        self._half = round(extent / cell / 2)
        side = 2 * self._half
        self.score = np.zeros((side, side), dtype=np.int8)
        self._flags = np.zeros(side * side, dtype=np.uint8)  # scratch of the cell marking: all zero between scans
        self._low = np.array([side, side])  # bounding box of the cells seen so far (index, inclusive low)
        self._high = np.array([0, 0])  # exclusive high

    def index(self, xy: np.ndarray) -> np.ndarray:
        """Grid indices (..., 2) of odometry-frame points (..., 2)."""
        return np.floor(xy / self.cell).astype(np.int64) + self._half

    def centre(self, index: np.ndarray) -> np.ndarray:
        """Odometry-frame centres (..., 2) of grid indices (..., 2)."""
        return (index - self._half + 0.5) * self.cell

    def never_occupied(self, xy: np.ndarray) -> np.ndarray:
        """Per odometry-frame point (P, 2): whether no cell of the 3 × 3 block around its cell has ever scored
        occupied (all seen free, or never seen): a hit there is something that was not there before."""
        if not len(xy):
            return np.zeros(0, dtype=bool)
        side = self.score.shape[0]
        cells = np.clip(self.index(xy), 1, side - 2)
        worst = np.full(len(xy), np.iinfo(np.int8).min, dtype=np.int64)
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                worst = np.maximum(worst, self.score[cells[:, 0] + di, cells[:, 1] + dj])
        return worst <= 0

    def observe(self, origin: np.ndarray, ends: np.ndarray, hit: np.ndarray, body: np.ndarray | None = None) -> None:
        """Account for one scan: beams from ``origin`` (2,) to ``ends`` (N, 2), odometry frame; ``hit`` says
        which ended on something (the others reached the range limit). Points of ``body`` (P, 2), where the
        robot stands (which its laser does not see), count as free too."""
        lengths = np.hypot(*(ends - origin).T)
        steps = np.arange(SAMPLE_STEP, lengths.max(initial=0.0), SAMPLE_STEP)
        # A beam marks free the cells it crosses up to a cell short of where it ended (its end cell may be a
        # wall); a cell crossed by several beams counts once.
        body = np.zeros((0, 2)) if body is None else np.ascontiguousarray(body, dtype=np.float64)
        bounds = kernels.mark_scan(
            self.score.reshape(-1), self._flags, np.ascontiguousarray(origin, dtype=np.float64),
            np.ascontiguousarray(ends, dtype=np.float64), np.ascontiguousarray(hit, dtype=np.bool_), lengths, steps,
            body, self.cell, self._half, self.score.shape[0], PASS, HIT, CLIP)
        if bounds[0] <= bounds[2]:
            self._low = np.minimum(self._low, bounds[:2])
            self._high = np.maximum(self._high, bounds[2:] + 1)

    def route(self, start: tuple[float, float], wanted: Callable[[np.ndarray], np.ndarray]) -> np.ndarray | None:
        """The shortest route (K, 2 odometry-frame cell centres, from ``start`` on) through free cells to the
        nearest wanted place, None if none is reachable. ``wanted`` says of cell centres (P, 2) whether they
        are still wanted; a place is a wanted free cell with WANTED_SHARE of its block wanted too, so a route
        never ends at a lone stray cell."""
        if np.any(self._high <= self._low):
            return None
        low, high = self._low - 1, self._high + 1  # one cell of border, never free, so no neighbour wraps round
        free = self.score[low[0]: high[0], low[1]: high[1]] < 0
        free[[0, -1], :] = False
        free[:, [0, -1]] = False
        rows, cols = free.shape
        start_cell = self.index(np.array(start)) - low
        if not (0 < start_cell[0] < rows - 1 and 0 < start_cell[1] < cols - 1):
            return None
        free[start_cell[0], start_cell[1]] = True  # the robot's own cell, whatever its score
        places = np.argwhere(free)
        want = np.zeros_like(free)
        want[places[:, 0], places[:, 1]] = wanted(self.centre(places + low))
        goal = want & (_block_share(want, WANTED_BLOCK) >= WANTED_SHARE)
        distance = _breadth_first(free.reshape(-1), goal.reshape(-1), start_cell[0] * cols + start_cell[1], cols)
        if distance is None:
            return None
        steps, cell, reached = distance
        path = [cell]
        for d in range(steps - 1, -1, -1):  # walk back down the distances to the start
            cell = next(n for n in (cell - 1, cell + 1, cell - cols, cell + cols) if reached[n] == d)
            path.append(cell)
        cells = np.array(path[::-1])
        return self.centre(np.stack([cells // cols, cells % cols], axis=-1) + low)


def _breadth_first(free: np.ndarray, goal: np.ndarray, start: int, cols: int) -> tuple[int, int, np.ndarray] | None:
    """Breadth-first search over 4-connected free cells (flat indices, a border of non-free cells) from
    ``start`` until a goal cell is reached: (its distance, the cell, the distances so far), None if none is."""
    distance = np.full(free.shape, -1, dtype=np.int32)
    distance[start] = 0
    wave, step = np.array([start]), 0
    offsets = np.array([-1, 1, -cols, cols])
    while len(wave):
        if goal[wave].any():
            return step, int(wave[goal[wave]][0]), distance
        step += 1
        neighbours = np.unique((wave[:, None] + offsets).reshape(-1))
        wave = neighbours[free[neighbours] & (distance[neighbours] < 0)]
        distance[wave] = step
    return None


def _block_share(mask: np.ndarray, side: int) -> np.ndarray:
    """The share of true cells in the ``side`` × ``side`` block centred on each cell (zero padded)."""
    pad = side // 2
    total = np.pad(mask.astype(np.int32), pad).cumsum(axis=0).cumsum(axis=1)
    total = np.pad(total, ((1, 0), (1, 0)))
    rows, cols = mask.shape
    sums = (total[side: side + rows, side: side + cols] - total[:rows, side: side + cols]
            - total[side: side + rows, :cols] + total[:rows, :cols])
    return sums / float(side * side)


def route_heading(route: np.ndarray, pose: tuple[float, float, float], ahead: float) -> tuple[float, float]:
    """Relative heading towards the route's point ``ahead`` m beyond the route point nearest the robot, and
    how far the robot is from the route."""
    gaps = np.hypot(route[:, 0] - pose[0], route[:, 1] - pose[1])
    nearest = int(np.argmin(gaps))
    along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(route, axis=0).T))])
    target = route[min(int(np.searchsorted(along, along[nearest] + ahead)), len(route) - 1)]
    return float(wrap(math.atan2(target[1] - pose[1], target[0] - pose[0]) - pose[2])), float(gaps[nearest])
