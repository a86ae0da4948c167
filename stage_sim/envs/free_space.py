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
from functools import cached_property

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
#: Windows around an episode's obstacles tried before the whole grid is labelled, each this many times wider
#: than the last (:meth:`FreeSpace._index_near`).
WINDOW_TRIES = 3
WINDOW_GROWTH = 3
#: The share of the grid the windows may cover: past it the whole grid is labelled at once.
WINDOWS_SHARE = 0.25


class PlacementError(ValueError):
    """The world has no room for the requested robots, goals or separations."""


class FreeSpace:
    """The valid centres for the robots of ``sim`` (the largest of them, with ``margin`` to spare)."""

    def __init__(self, sim: Simulation, robots: list[int], margin: float) -> None:
        static = sim.static
        static.grid.check_dense("placing robots in free space (a distance transform of the whole world)")
        self._static = static
        """The raster this is the free space of."""
        self._robots = robots
        self._margin = margin
        self._bodies = list(static.bodies)
        self._blocked: np.ndarray | None = self._blocked_of(sim)
        """The cells no part of a robot may cover (:attr:`blocked_cells`); None in a space derived from another
        (:meth:`with_world`), which holds what it adds instead: ``_blocked_from``."""
        self._blocked_from: tuple[FreeSpace, list[StaticBody]] | None = None
        self.shape = static.shape
        self.radius = max(sim.robots[i].radius for i in robots)
        self._reach = self.radius + margin + static.resolution
        """A valid centre is farther than this (m) from every blocking cell."""
        self.resolution = static.resolution
        self._pad = int(self._reach / self.resolution) + 1
        """Cells around a blocking cell that can be within the reach of it."""
        self.origin = np.asarray(static.origin_xy, dtype=np.float64)
        self.width = static.shape[1]
        self._compiled = sim.kernels == "numba"
        """Whether draws test their candidates with the compiled twin (the same answers)."""
        padded = np.pad(self._blocked, 1, constant_values=True)  # the grid's edge blocks too
        if sim.kernels == "numba":
            from stage_sim.envs.free_space_kernels import clear_near

            valid = np.ones(padded.shape, dtype=bool)
            clear_near(valid, padded, self._spans)
            valid = np.ascontiguousarray(valid[1:-1, 1:-1])
        else:
            valid = ndimage.distance_transform_edt(~padded)[1:-1, 1:-1] * static.resolution > self._reach
        self._index(valid, sim.kernels == "numba")

    def with_world(self, sim: Simulation) -> FreeSpace:
        """The free space of ``sim``, whose world is this one's with more static bodies (an episode's
        obstacles): only the cells near the new bodies are looked at again, with the same distances and
        comparison as the whole-world transform, so the answer is the one a new :class:`FreeSpace` gives.
        A world that differs otherwise (another grid, a body gone) gets a new FreeSpace; this very raster (a
        vector env's worlds of one world file share it) gets this one."""
        static = sim.static
        if static is self._static:
            return self
        same_grid = (static.shape == self.shape and static.resolution == self.resolution
                     and np.array_equal(np.asarray(static.origin_xy, dtype=np.float64), self.origin))
        if not same_grid:
            return FreeSpace(sim, self._robots, self._margin)
        bodies = self._added_bodies(sim)
        lost = None
        if bodies is None:  # not this world's bodies and more: only a grid that lost no blocked cell is redone here
            blocked, mine = self._blocked_of(sim), self.blocked_cells
            if (mine & ~blocked).any():
                return FreeSpace(sim, self._robots, self._margin)
            added = blocked & ~mine
            boxes = _clusters(added, np.flatnonzero(added))
            valid = self._cleared_near(added, boxes)
        elif sim.kernels == "numba":
            from stage_sim.envs.free_space_kernels import add_bodies

            blocked, valid = self.blocked_cells.copy(), self.valid_centres.copy()
            lost, found = (add_bodies(blocked, valid, bodies, self._spans) if bodies
                           else (np.zeros(0, dtype=np.int64), np.zeros((0, 4), dtype=np.int64)))
            boxes = [(slice(r0, r1), slice(c0, c1)) for r0, r1, c0, c1 in found.tolist()]
        else:
            blocked, boxes = self._blocked_with(bodies)
            valid = self._cleared_near(self._added_within(blocked, boxes), boxes)
        space = copy.copy(self)
        space.__dict__.pop("_rank", None)  # this space's, not the copy's
        space._static, space._bodies = static, list(static.bodies)
        if bodies is None:
            space._blocked, space._blocked_from = blocked, None
        else:  # this space and the bodies, not a grid: an episode's space holds no copy of the whole world
            space._blocked, space._blocked_from = None, (self, bodies)
        space._compiled = sim.kernels == "numba"
        space._index_near(self, valid, boxes, self._pad + 1, sim.kernels == "numba", lost)
        return space

    def _cleared_near(self, added: np.ndarray, boxes: list[tuple[slice, slice]]) -> np.ndarray:
        """This space's valid centres less those within reach of the ``added`` blocked cells, all within
        ``boxes``: a distance transform around each box (the numpy reference of
        :func:`~stage_sim.envs.free_space_kernels.add_bodies`)."""
        valid = self.valid_centres.copy()
        pad = self._pad
        for rows, cols in boxes:
            window = (slice(max(rows.start - pad, 0), rows.stop + pad),
                      slice(max(cols.start - pad, 0), cols.stop + pad))
            clearance = ndimage.distance_transform_edt(~added[window]) * self.resolution
            valid[window] &= clearance > self._reach
        return valid

    @cached_property
    def _spans(self) -> np.ndarray:
        """The cells no farther than the reach from a cell, by the distance a distance transform computes
        (``sqrt(dy² + dx²)`` cells times the resolution), row by row: (R, 3) row offset, first and last column
        offset (the distance grows with the column offset, so each row's cells are one run); the pad bounds
        them."""
        pad = self._pad
        rows, cols = np.mgrid[-pad:pad + 1, -pad:pad + 1]
        distance = np.sqrt((rows * rows + cols * cols).astype(np.float64)) * self.resolution
        near = ~(distance > self._reach)
        held = near.any(axis=1)
        last = np.where(near, cols, -pad - 1).max(axis=1)
        return np.ascontiguousarray(np.column_stack([rows[held, 0], -last[held], last[held]]).astype(np.int64))

    @cached_property
    def _rank(self) -> np.ndarray:
        """Per flat grid cell, the position of a valid centre among :attr:`cells` (int32; what the others hold
        means nothing): where the cells an episode's obstacles take lie among this space's, without a search
        through some 340,000 of them."""
        return np.cumsum(self.valid_centres.ravel(), dtype=np.int32) - 1

    def _blocked_of(self, sim: Simulation) -> np.ndarray:
        """Cells no part of a robot may cover: the filled bodies of every height band of the robots."""
        blocked = np.zeros(sim.static.shape, dtype=bool)
        for band in {sim.robots[i].z_band for i in self._robots}:
            blocked |= sim.static.filled_collision_layer(*band)
        return blocked

    def _added_bodies(self, sim: Simulation) -> list[StaticBody] | None:
        """The bodies of ``sim`` after this world's that block its robots, when its bodies begin with this world's,
        the very objects (an episode's world, :meth:`~stage_sim.sim.simulation.Simulation.with_static_models`);
        None otherwise."""
        bodies = sim.static.bodies
        if len(bodies) < len(self._bodies) or any(a is not b for a, b in zip(self._bodies, bodies, strict=False)):
            return None
        bands = {sim.robots[i].z_band for i in self._robots}
        return [body for body in bodies[len(self._bodies):]
                if body.outline.size and any(body.blocks(*band) for band in bands)]

    def _blocked_with(self, bodies: list[StaticBody]) -> tuple[np.ndarray, list[tuple[slice, slice]]]:
        """This space's blocked cells and the filled footprints of ``bodies`` (on its grid), with a box (rows, cols)
        holding each footprint."""
        blocked = self.blocked_cells.copy()
        boxes = []
        for body in bodies:
            blocked.ravel()[body.cells] = True
            # its filled cells lie within its outline's box (a cell wider: the fill and the outline round the same
            # vertices each its own way)
            rows, cols = np.divmod(body.outline, self.width)
            boxes.append((slice(max(int(rows[0]) - 1, 0), int(rows[-1]) + 2),
                          slice(max(int(cols.min()) - 1, 0), int(cols.max()) + 2)))
        return blocked, boxes

    def _added_within(self, blocked: np.ndarray, boxes: list[tuple[slice, slice]]) -> np.ndarray:
        """The cells ``blocked`` holds and this space's blocked cells do not, all within ``boxes`` (what
        ``blocked & ~self.blocked_cells`` gives, without a pass over the whole grid)."""
        added, mine = np.zeros_like(blocked), self.blocked_cells
        for rows, cols in boxes:
            added[rows, cols] = blocked[rows, cols] & ~mine[rows, cols]
        return added

    def _index(self, valid: np.ndarray, compiled: bool) -> None:
        """Regions and cells of the valid centres ``valid`` (a grid of bools); ``compiled``: label them with the
        compiled twin of scipy's labelling (:mod:`stage_sim.envs.free_space_kernels`, the same labels)."""
        self._valid: np.ndarray | None = valid
        regions, self._count = _label(valid, compiled)
        self._regions: np.ndarray | None = regions
        cells = np.flatnonzero(valid)
        self._cells: np.ndarray | _CellIndex = cells
        if self._count == 1:  # the common case needs no sorting by region
            self._region_cells: list[np.ndarray | _CellIndex] = [cells]
        else:
            labels = regions.ravel()[cells]
            order = np.argsort(labels, kind="stable")
            ends = np.searchsorted(labels[order], np.arange(1, self._count + 2))
            self._region_cells = [cells[order[a:b]] for a, b in itertools.pairwise(ends)]
        """The valid cells of region r at index r - 1, in increasing order."""
        self._check_room()

    def _index_near(self, base: FreeSpace, valid: np.ndarray, boxes: list[tuple[slice, slice]], reach: int,
                    compiled: bool, lost: np.ndarray | None = None) -> None:
        """:meth:`_index` of ``valid``, which is ``base``'s valid centres less some within ``reach`` - 1 cells of
        ``boxes``, without labelling the whole grid when it can. Around the boxes, windows wider than that
        (disjoint: overlapping ones merged): if ``base`` is one region and the valid centres of every window
        are one region within it, so is ``valid`` (a path between two centres that crossed a lost cell enters
        its window at a centre and leaves it at one of its outer cells, never lost; the two are joined inside
        the window), and its cells are ``base``'s less those lost, looked up in ``base``'s without a copy
        (:class:`_CellIndex`), as are its valid centres (``valid`` is not kept: an episode's space holds no grid of
        the whole world). A window split in two may join around its obstacle a little farther out: the
        windows are tried :data:`WINDOW_TRIES` times, wider each time, while they cover at most
        :data:`WINDOWS_SHARE` of the grid; then the whole grid is labelled. ``lost``: the flat cells ``base`` holds
        and ``valid`` does not, sorted, when known (else found in the windows)."""
        windows = None
        if base._count == 1:
            for widen in range(WINDOW_TRIES):
                tried = _windows(boxes, reach * WINDOW_GROWTH**widen, valid.shape)
                area = sum((rows.stop - rows.start) * (cols.stop - cols.start) for rows, cols in tried)
                if area > valid.size * WINDOWS_SHARE:  # labelling the whole grid costs little more
                    break
                if all(_label(valid[window], compiled)[1] <= 1 for window in tried):
                    windows = tried
                    break
        if windows is None:
            self._index(valid, compiled)
            return
        base_valid = base.valid_centres
        if lost is None:
            local = [np.flatnonzero(base_valid[window] & ~valid[window]) for window in windows]
            flat = [(rows.start + cells // (cols.stop - cols.start)) * self.width + cols.start
                    + cells % (cols.stop - cols.start) for (rows, cols), cells in zip(windows, local, strict=True)]
            lost = np.sort(np.concatenate([np.zeros(0, dtype=np.int64), *flat]))
        positions = base._rank[lost].astype(np.int64)
        self._valid = None  # the base's valid centres less ``lost``: those two, not a grid of its own
        self._lost_from = (base_valid, lost)
        self._count = 1
        self._regions = None
        self._cells = _CellIndex(base.cells, positions)
        self._region_cells = [self._cells]
        self._check_room()

    def _check_room(self) -> None:
        if len(self._cells) == 0:
            raise PlacementError(f"no free space wide enough for a robot of radius {self.radius:.2f} m")

    @property
    def cells(self) -> np.ndarray:
        """The valid centres' flat cells, in increasing order."""
        return np.asarray(self._cells)

    @property
    def regions(self) -> np.ndarray:
        """(H, W) int32 region label of every cell (0: not a valid centre), numbered as scipy's 8-connected
        labelling numbers them."""
        if self._regions is None:  # one region: its label is 1
            self._regions = self.valid_centres.astype(np.int32)
        return self._regions

    @property
    def blocked_cells(self) -> np.ndarray:
        """(H, W) bool: the cells no part of a robot may cover (a derived space makes the grid on request from
        its base's and the bodies it adds)."""
        if self._blocked is None:
            assert self._blocked_from is not None
            base, bodies = self._blocked_from
            blocked = base.blocked_cells.copy()
            for body in bodies:
                blocked.ravel()[body.cells] = True
            return blocked
        return self._blocked

    @property
    def valid_centres(self) -> np.ndarray:
        """(H, W) bool: whether each cell is a valid centre (an episode's space of one region makes the grid on
        request: it holds only what its base's lost)."""
        if self._valid is None:
            base_valid, lost = self._lost_from
            valid = base_valid.copy()
            valid.ravel()[lost] = False
            return valid
        return self._valid

    def centres(self, cells: np.ndarray) -> np.ndarray:
        """World (x, y) of the centres of flat cell indices."""
        rows, cols = np.divmod(cells, self.width)
        xs, ys = self._axes
        out = np.empty((len(cells), 2))
        out[:, 0], out[:, 1] = xs[cols], ys[rows]
        return out

    @cached_property
    def _axes(self) -> tuple[np.ndarray, np.ndarray]:
        """The x of every column's centres and the y of every row's (``origin + (index + 0.5) · resolution``):
        a draw looks its candidates up rather than working them out."""
        height = self.shape[0]
        return (self.origin[0] + (np.arange(self.width) + 0.5) * self.resolution,
                self.origin[1] + (np.arange(height) + 0.5) * self.resolution)

    def region_of(self, points: np.ndarray) -> np.ndarray:
        """Region label at world points (0: not a valid centre)."""
        cols, rows = np.floor((np.asarray(points) - self.origin) / self.resolution).astype(np.int64).T
        inside = (rows >= 0) & (rows < self.shape[0]) & (cols >= 0) & (cols < self.width)
        labels = np.zeros(len(rows), dtype=np.int32)
        if self._regions is not None:
            labels[inside] = self._regions[rows[inside], cols[inside]]
        elif self._valid is not None:  # one region: valid is its label
            labels[inside] = self._valid[rows[inside], cols[inside]]
        else:  # one region, the base's valid centres less those lost
            base_valid, lost = self._lost_from
            flat = rows[inside] * self.width + cols[inside]
            at = np.minimum(np.searchsorted(lost, flat), max(lost.size - 1, 0))
            gone = lost[at] == flat if lost.size else np.zeros(flat.size, dtype=bool)
            labels[inside] = base_valid.ravel()[flat] & ~gone
        return labels

    def draw(
        self, rng: np.random.Generator, avoid: np.ndarray, separation: float, region: int = 0,
        away_from: np.ndarray | None = None, min_distance: float = 0.0, excluded: frozenset[int] = frozenset(),
        compiled: bool | None = None,
    ) -> np.ndarray:
        """One valid point at least ``separation`` from every row of ``avoid`` (M, 2), in ``region`` (0: any
        but ``excluded``) and at least ``min_distance`` from ``away_from``; PlacementError if none exists.
        ``compiled``: test the candidates with the compiled twin (the same answers; default: when this space's
        simulation runs the numba kernels)."""
        pool = self._pool(region, excluded)
        fits = _Fits(avoid, separation, away_from, min_distance)
        if len(pool):
            for _ in range(QUICK_BATCHES):
                positions = rng.integers(len(pool), size=BATCH)
                if self._compiled if compiled is None else compiled:
                    point = self._first_fit(pool, positions, fits)
                    if point is not None:
                        return point
                    continue
                points = self.centres(pool.take(positions))
                ok = fits(points)
                if ok.any():
                    return points[np.argmax(ok)]
            every = self.centres(np.asarray(pool))
            ok = np.flatnonzero(fits(every))
            if ok.size:
                return every[ok[rng.integers(ok.size)]]
        raise PlacementError(
            f"no room for a robot {separation:.2f} m from the others"
            + (f" and {min_distance:.2f} m from its start" if away_from is not None else "")
            + ": use fewer robots, a shorter goal distance or a larger world")

    def _first_fit(self, pool: np.ndarray | _CellIndex, positions: np.ndarray, fits: _Fits) -> np.ndarray | None:
        """The centre of the first candidate at ``positions`` of ``pool`` that ``fits``, or None: a batch of
        :meth:`draw` in one compiled pass (:func:`~stage_sim.envs.free_space_kernels.first_fit`)."""
        from stage_sim.envs.free_space_kernels import first_fit

        cells, shift = (pool.base, pool.shift) if isinstance(pool, _CellIndex) else (pool, _NONE_REMOVED)
        xs, ys = self._axes
        away = _NO_POINT if fits.away_from is None else np.asarray(fits.away_from, dtype=np.float64)
        point = np.empty(2)
        found = first_fit(cells, shift, positions, self.width, xs, ys, fits.avoid, fits.separation, away,
                          fits.min_distance, point)
        return point if found >= 0 else None

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

    def _pool(self, region: int, excluded: frozenset[int]) -> np.ndarray | _CellIndex:
        """The valid cells of ``region`` (0: of every region but ``excluded``)."""
        if region:
            return self._region_cells[region - 1]
        if excluded:
            return np.concatenate([c for r, c in enumerate(self._region_cells, 1) if r not in excluded] or [[]])
        return self._cells


def _label(valid: np.ndarray, compiled: bool) -> tuple[np.ndarray, int]:
    """The 8-connected regions of ``valid`` and their count: scipy's labelling or (``compiled``) its twin."""
    if compiled:
        from stage_sim.envs.free_space_kernels import label8

        return label8(valid)
    regions, count = ndimage.label(valid, structure=np.ones((3, 3), dtype=bool))
    return regions, int(count)


def _windows(boxes: list[tuple[slice, slice]], margin: int, shape: tuple[int, ...]) -> list[tuple[slice, slice]]:
    """``boxes`` widened by ``margin`` cells on every side (cut to the grid), overlapping ones merged into their
    bounding box until none overlap."""
    spans = [[max(r.start - margin, 0), min(r.stop + margin, shape[0]), max(c.start - margin, 0),
              min(c.stop + margin, shape[1])] for r, c in boxes]
    merged = True
    while merged:
        merged = False
        for i, j in itertools.combinations(range(len(spans)), 2):
            a, b = spans[i], spans[j]
            if a[0] < b[1] and b[0] < a[1] and a[2] < b[3] and b[2] < a[3]:
                spans[i] = [min(a[0], b[0]), max(a[1], b[1]), min(a[2], b[2]), max(a[3], b[3])]
                del spans[j]
                merged = True
                break
    return [(slice(r0, r1), slice(c0, c1)) for r0, r1, c0, c1 in spans]


_NONE_REMOVED = np.zeros(0, dtype=np.int64)
_NO_POINT = np.zeros(0)


class _CellIndex:
    """Sorted flat cells: ``base``'s (sorted) less those at the sorted positions ``removed``, looked up without
    copying the rest (an episode's obstacles take a few thousand of some 340,000 valid centres, and a copy of
    them cost more than the labelling it saves). :meth:`take` answers as the array's ``take``."""

    def __init__(self, base: np.ndarray, removed: np.ndarray) -> None:
        self._base = base
        self._removed = removed
        self._shift = removed - np.arange(removed.size)
        """Position k of the rest is position k + (how many of these are <= k) of ``base``."""
        self._array: np.ndarray | None = None

    def __len__(self) -> int:
        return self._base.size - self._removed.size

    @property
    def base(self) -> np.ndarray:
        return self._base

    @property
    def shift(self) -> np.ndarray:
        """Per removed position, how many positions of the rest come before it (what :meth:`take` searches)."""
        return self._shift

    def take(self, positions: np.ndarray) -> np.ndarray:
        return self._base[positions + np.searchsorted(self._shift, positions, side="right")]

    def __array__(self, dtype: np.dtype | None = None, copy: bool | None = None) -> np.ndarray:
        if self._array is None:
            self._array = np.delete(self._base, self._removed)
        return np.array(self._array, dtype=dtype, copy=copy)


def _clusters(mask: np.ndarray, cells: np.ndarray) -> list[tuple[slice, slice]]:
    """Boxes (rows, cols) that hold every set cell of ``mask`` (its flat ``cells``: np.nonzero of a 2-D grid is
    ten times slower) between them, one per 8-connected group of the :data:`CLUSTER_BLOCK`-cell blocks holding
    one, each cut to its cells: the places an episode's obstacles changed, found without labelling the whole
    grid (how cells are grouped changes no answer of :meth:`FreeSpace.with_world`, only the size of its
    windows)."""
    rows, cols = np.divmod(cells, mask.shape[1])
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

    #: Candidate-point pairs up to which every distance is computed at once; past it (the look at every valid
    #: cell) a k-d tree of ``avoid`` answers. Both compute sqrt(dx² + dy²), so they agree to the bit.
    PAIRS_AT_ONCE = 1 << 16

    def __init__(self, avoid: np.ndarray, separation: float, away_from: np.ndarray | None, min_distance: float):
        self.avoid = np.ascontiguousarray(np.asarray(avoid, dtype=np.float64).reshape(-1, 2))
        self.separation = separation
        self.away_from = away_from
        self.min_distance = min_distance

    def __call__(self, points: np.ndarray) -> np.ndarray:
        ok = np.ones(len(points), dtype=bool)
        if len(self.avoid) and len(points) * len(self.avoid) <= self.PAIRS_AT_ONCE:
            dx = np.subtract.outer(points[:, 0], self.avoid[:, 0])
            dy = np.subtract.outer(points[:, 1], self.avoid[:, 1])
            ok &= np.sqrt((dx * dx + dy * dy).min(axis=1)) >= self.separation
        elif len(self.avoid):
            nearest, _ = cKDTree(self.avoid).query(points, distance_upper_bound=self.separation)
            ok &= nearest >= self.separation
        if self.away_from is not None:
            ok &= np.linalg.norm(points - self.away_from, axis=1) >= self.min_distance
        return ok
