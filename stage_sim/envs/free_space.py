"""Where a robot may start and where its goal may be: free space with room for the body, reachable.

A cell is a valid centre when the nearest cell that blocks the robots is farther than the robot's radius plus
a margin, measured by an exact Euclidean distance transform. What blocks is the *filled* footprint of every
static body that the robots collide with (the grid's edge included): contacts and rays see only a block's
outline, as in Stage, so a robot drawn inside a block would never notice it. Valid cells are grouped into
8-connected regions, so that a goal is always drawn in the region of its start: a robot is never asked to
reach a closed room.

Draws are uniform over the valid cells that keep the required distances: a few batches of random candidates
first (the common, cheap case), then, if none fits, every valid cell at once, so a draw fails only when no
cell fits at all. A start whose region has no room for its goal is drawn again from the other regions. All
draws come from the caller's generator.
"""

from __future__ import annotations

import copy
import itertools

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from stage_sim.maps.raster import StaticBody
from stage_sim.sim.simulation import Simulation

#: Candidates drawn per batch, and batches tried, before every valid cell is looked at.
BATCH = 64
QUICK_BATCHES = 4
#: Side (cells) of the blocks in which :func:`_clusters` looks for new bodies.
CLUSTER_BLOCK = 32


class PlacementError(ValueError):
    """The world has no room for the requested robots, goals or separations."""


class FreeSpace:
    """The valid centres for the robots of ``sim`` (the largest of them, with ``margin`` to spare)."""

    def __init__(self, sim: Simulation, robots: list[int], margin: float) -> None:
        static = sim.static
        static.grid.check_dense("placing robots in free space (a distance transform of the whole world)")
        self._robots = robots
        self._margin = margin
        self._bodies = list(static.bodies)
        self._blocked = self._blocked_of(sim)
        self.radius = max(sim.robots[i].radius for i in robots)
        self._reach = self.radius + margin + static.resolution
        """A valid centre is farther than this (m) from every blocking cell."""
        self.resolution = static.resolution
        self._pad = int(self._reach / self.resolution) + 1
        """Cells around a blocking cell that can be within the reach of it."""
        self.origin = np.asarray(static.origin_xy, dtype=np.float64)
        self.width = static.shape[1]
        padded = np.pad(self._blocked, 1, constant_values=True)  # the grid's edge blocks too
        if sim.kernels == "numba":
            from stage_sim.envs.free_space_kernels import clear_near

            valid = np.ones(padded.shape, dtype=bool)
            clear_near(valid, padded, np.flatnonzero(padded), self._near_offsets(self._pad))
            valid = np.ascontiguousarray(valid[1:-1, 1:-1])
        else:
            valid = ndimage.distance_transform_edt(~padded)[1:-1, 1:-1] * static.resolution > self._reach
        self._index(valid, sim.kernels == "numba")

    def with_world(self, sim: Simulation) -> FreeSpace:
        """The free space of ``sim``, whose world is this one's with more static bodies (an episode's
        obstacles): only the cells near the new bodies are looked at again, with the same distances and
        comparison as the whole-world transform, so the answer is the one a new :class:`FreeSpace` gives.
        A world that differs otherwise (another grid, a body gone) gets a new FreeSpace."""
        static = sim.static
        same_grid = (static.shape == self._blocked.shape and static.resolution == self.resolution
                     and np.array_equal(np.asarray(static.origin_xy, dtype=np.float64), self.origin))
        blocked = self._blocked_with(sim) if same_grid else None
        if blocked is None or (self._blocked & ~blocked).any():
            return FreeSpace(sim, self._robots, self._margin)
        added = blocked & ~self._blocked
        valid = self._valid.copy()
        pad = self._pad
        if sim.kernels == "numba":
            from stage_sim.envs.free_space_kernels import clear_near

            clear_near(valid, added, np.flatnonzero(added), self._near_offsets(pad))
        else:
            for rows, cols in _clusters(added):
                window = (slice(max(rows.start - pad, 0), rows.stop + pad),
                          slice(max(cols.start - pad, 0), cols.stop + pad))
                clearance = ndimage.distance_transform_edt(~added[window]) * self.resolution
                valid[window] &= clearance > self._reach
        space = copy.copy(self)
        space._bodies = list(static.bodies)
        space._blocked = blocked
        space._index(valid, sim.kernels == "numba")
        return space

    def _near_offsets(self, pad: int) -> np.ndarray:
        """(K, 2) offsets (rows, cols) of the cells no farther than the reach from a cell, by the distance a
        distance transform computes (``sqrt(dy² + dx²)`` cells times the resolution); ``pad`` bounds them."""
        rows, cols = np.mgrid[-pad:pad + 1, -pad:pad + 1]
        distance = np.sqrt((rows * rows + cols * cols).astype(np.float64)) * self.resolution
        near = ~(distance > self._reach)
        return np.ascontiguousarray(np.column_stack([rows[near], cols[near]]).astype(np.int64))

    def _blocked_of(self, sim: Simulation) -> np.ndarray:
        """Cells no part of a robot may cover: the filled bodies of every height band of the robots."""
        blocked = np.zeros(sim.static.shape, dtype=bool)
        for band in {sim.robots[i].z_band for i in self._robots}:
            blocked |= sim.static.filled_collision_layer(*band)
        return blocked

    def _blocked_with(self, sim: Simulation) -> np.ndarray:
        """:meth:`_blocked_of` ``sim`` (on this grid): this world's blocked cells and those of the bodies added
        after this world's when its bodies come first, the very objects (an episode's world,
        :meth:`~stage_sim.sim.simulation.Simulation.with_static_models`), else worked out anew."""
        bodies = sim.static.bodies
        if len(bodies) < len(self._bodies) or any(a is not b for a, b in zip(self._bodies, bodies, strict=False)):
            return self._blocked_of(sim)
        bands = {sim.robots[i].z_band for i in self._robots}
        blocked = self._blocked.copy()
        mark = _mark_filled
        if sim.kernels == "numba":
            from stage_sim.envs.free_space_kernels import mark_filled as mark
        for body in bodies[len(self._bodies):]:
            if any(body.blocks(*band) for band in bands):
                mark(blocked, body)
        return blocked

    def _index(self, valid: np.ndarray, compiled: bool) -> None:
        """Regions and cells of the valid centres ``valid`` (a grid of bools); ``compiled``: label them with the
        compiled twin of scipy's labelling (:mod:`stage_sim.envs.free_space_kernels`, the same labels)."""
        self._valid = valid
        if compiled:
            from stage_sim.envs.free_space_kernels import label8

            self.regions, count = label8(valid)
        else:
            self.regions, count = ndimage.label(valid, structure=np.ones((3, 3), dtype=bool))
        self.cells = np.flatnonzero(valid)
        if count == 1:  # the common case needs no sorting by region
            self._region_cells = [self.cells]
        else:
            labels = self.regions.ravel()[self.cells]
            order = np.argsort(labels, kind="stable")
            ends = np.searchsorted(labels[order], np.arange(1, count + 2))
            self._region_cells = [self.cells[order[a:b]] for a, b in itertools.pairwise(ends)]
        """The valid cells of region r at index r - 1, in increasing order."""
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
        away_from: np.ndarray | None = None, min_distance: float = 0.0, excluded: frozenset[int] = frozenset(),
    ) -> np.ndarray:
        """One valid point at least ``separation`` from every row of ``avoid`` (M, 2), in ``region`` (0: any
        but ``excluded``) and at least ``min_distance`` from ``away_from``; PlacementError if none exists."""
        pool = self._pool(region, excluded)
        fits = _Fits(avoid, separation, away_from, min_distance)
        if pool.size:
            for _ in range(QUICK_BATCHES):
                points = self.centres(pool[rng.integers(len(pool), size=BATCH)])
                ok = fits(points)
                if ok.any():
                    return points[np.argmax(ok)]
            every = self.centres(pool)
            ok = np.flatnonzero(fits(every))
            if ok.size:
                return every[ok[rng.integers(ok.size)]]
        raise PlacementError(
            f"no room for a robot {separation:.2f} m from the others"
            + (f" and {min_distance:.2f} m from its start" if away_from is not None else "")
            + ": use fewer robots, a shorter goal distance or a larger world")

    def starts_and_goals(
        self, rng: np.random.Generator, count: int, fixed: np.ndarray, min_goal_distance: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """``count`` start poses (x, y, yaw) and goals (x, y), clear of each other and of ``fixed`` (M, 2)."""
        separation = 2 * self.radius + self.resolution
        starts = np.empty((count, 3))
        goals = np.empty((count, 2))
        for i in range(count):
            placed = np.concatenate([fixed.reshape(-1, 2), starts[:i, :2]])
            taken = np.concatenate([fixed.reshape(-1, 2), goals[:i]])
            excluded: set[int] = set()  # regions found to have no room for a goal
            while True:
                start = self.draw(rng, placed, separation, excluded=frozenset(excluded))
                region = int(self.region_of(start[None])[0])
                try:
                    goal = self.draw(rng, taken, separation, region, start, min_goal_distance)
                    break
                except PlacementError:
                    excluded.add(region)
            starts[i] = (*start, rng.uniform(-np.pi, np.pi))
            goals[i] = goal
        return starts, goals

    def _pool(self, region: int, excluded: frozenset[int]) -> np.ndarray:
        """The valid cells of ``region`` (0: of every region but ``excluded``)."""
        if region:
            return self._region_cells[region - 1]
        if excluded:
            return np.concatenate([c for r, c in enumerate(self._region_cells, 1) if r not in excluded] or [[]])
        return self.cells


def _mark_filled(blocked: np.ndarray, body: StaticBody) -> None:
    """Set in ``blocked`` the cells of ``body``'s filled footprint (the numpy reference of
    :func:`~stage_sim.envs.free_space_kernels.mark_filled`)."""
    blocked.ravel()[body.cells] = True


def _clusters(mask: np.ndarray) -> list[tuple[slice, slice]]:
    """Boxes (rows, cols) that hold every set cell of ``mask`` between them, one per 8-connected group of the
    :data:`CLUSTER_BLOCK`-cell blocks holding one, each cut to its cells: the places an episode's obstacles
    changed, found without labelling the whole grid (how cells are grouped changes no answer of
    :meth:`FreeSpace.with_world`, only the size of its windows)."""
    rows, cols = np.divmod(np.flatnonzero(mask), mask.shape[1])  # np.nonzero of a 2-D grid is ten times slower
    if rows.size == 0:
        return []
    shape = (rows.max() // CLUSTER_BLOCK + 1, cols.max() // CLUSTER_BLOCK + 1)
    blocks = np.zeros(shape, dtype=bool)
    blocks[rows // CLUSTER_BLOCK, cols // CLUSTER_BLOCK] = True
    groups, _ = ndimage.label(blocks, structure=np.ones((3, 3), dtype=bool))
    boxes = []
    for block_rows, block_cols in ndimage.find_objects(groups):
        window = (slice(block_rows.start * CLUSTER_BLOCK, block_rows.stop * CLUSTER_BLOCK),
                  slice(block_cols.start * CLUSTER_BLOCK, block_cols.stop * CLUSTER_BLOCK))
        held_rows = np.flatnonzero(mask[window].any(axis=1)) + window[0].start
        held_cols = np.flatnonzero(mask[window].any(axis=0)) + window[1].start
        boxes.append((slice(held_rows[0], held_rows[-1] + 1), slice(held_cols[0], held_cols[-1] + 1)))
    return boxes


class _Fits:
    """Which candidate points keep ``separation`` from ``avoid`` and ``min_distance`` from ``away_from``."""

    def __init__(self, avoid: np.ndarray, separation: float, away_from: np.ndarray | None, min_distance: float):
        self.tree = cKDTree(avoid) if len(avoid) else None
        self.separation = separation
        self.away_from = away_from
        self.min_distance = min_distance

    def __call__(self, points: np.ndarray) -> np.ndarray:
        ok = np.ones(len(points), dtype=bool)
        if self.tree is not None:
            nearest, _ = self.tree.query(points, distance_upper_bound=self.separation)
            ok &= nearest >= self.separation
        if self.away_from is not None:
            ok &= np.linalg.norm(points - self.away_from, axis=1) >= self.min_distance
        return ok
