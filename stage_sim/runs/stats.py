"""What a run of wandering robots achieved: distance, stall events, longest stop and map coverage per robot.

Computed from the simulator's ground truth (not from what the robots believe), so that the launch scripts'
summaries judge a controller by what really happened.
"""

from __future__ import annotations

import math

import numpy as np

from stage_sim.maps.tiles import DENSE_CELL_LIMIT
from stage_sim.sim.simulation import Simulation

#: Most coarse cells of a coverage grid (one per robot; the connected free space is grown by dilation, which
#: costs side × cells): a larger world is covered in coarser cells.
COVERAGE_CELL_LIMIT = 1_000_000
# A robot stands still while it stays this close to one pose (m, rad): dithering between tiny turns or
# creeping back and forth is standing still too, not just a zero velocity.
STOP_RADIUS, STOP_TURN = 0.05, 0.1


class RunStats:
    """Per-robot distance, stall events, longest stop and coverage, from the ground truth of every step.

    A stop lasts from a pose until the robot first gets STOP_RADIUS or STOP_TURN away from it. Coverage is
    the share of the map's free cells (``cell`` m squares, coarser in a world of over
    :data:`COVERAGE_CELL_LIMIT` of them, whose fine cells are all free, 4-connected
    to a robot's start) that came within ``radius`` of the robot: a disc is stamped on a coarse grid wherever
    the robot enters a new cell.
    """

    def __init__(self, sim: Simulation, cell: float = 0.1, radius: float = 1.0) -> None:
        self.sim = sim
        static = sim.static
        height, width = static.shape
        factor = max(1, round(cell / static.resolution), math.ceil(math.sqrt(height * width / COVERAGE_CELL_LIMIT)))
        self.cell = factor * static.resolution
        self.origin = np.array(static.origin_xy, dtype=np.float64)
        rows, cols = height // factor, width // factor
        blocked = np.zeros((rows, cols), dtype=bool)  # a coarse cell holding any occupied fine cell
        for body in static.bodies:  # the filled footprints; only the outlines of a world too large for them
            r, c = np.divmod(body.cells if height * width <= DENSE_CELL_LIMIT else body.outline, width)
            keep = (r < rows * factor) & (c < cols * factor)
            blocked[r[keep] // factor, c[keep] // factor] = True
        starts = [self._cell_of(pose) for pose in sim.true_poses]
        self.free = _connected(~blocked, starts)
        reach = math.ceil(radius / self.cell)
        offsets = np.arange(-reach, reach + 1)
        self._disc = np.hypot(*np.meshgrid(offsets, offsets, indexing="ij")) * self.cell <= radius
        self._reach = reach
        n = len(sim.robots)
        self.covered = [np.zeros_like(self.free) for _ in range(n)]
        self._last_cell: list[tuple[int, int] | None] = [None] * n
        self.distance = np.zeros(n)
        self.stall_events = np.zeros(n, dtype=np.int64)
        self.longest_stop = np.zeros(n)
        self._anchors = sim.true_poses.copy()  # where each robot's current (possible) stop began, and when
        self._anchor_times = np.full(n, sim.sim_time)
        self._poses = sim.true_poses.copy()
        self._stalled = sim.stalled.copy()
        self._time = sim.sim_time
        for robot in range(n):
            self._stamp(robot)

    def _cell_of(self, pose: np.ndarray) -> tuple[int, int]:
        col, row = np.floor((pose[:2] - self.origin) / self.cell).astype(int)
        return int(row), int(col)

    def _stamp(self, robot: int) -> None:
        """Mark every coarse cell within the radius of the robot's current cell."""
        cell = self._cell_of(self.sim.true_poses[robot])
        if cell == self._last_cell[robot]:
            return
        self._last_cell[robot] = cell
        r, k = self._reach, self.covered[robot]
        rows, cols = k.shape
        r0, r1, c0, c1 = cell[0] - r, cell[0] + r + 1, cell[1] - r, cell[1] + r + 1
        window = k[max(r0, 0): min(r1, rows), max(c0, 0): min(c1, cols)]
        window |= self._disc[max(-r0, 0): self._disc.shape[0] - max(r1 - rows, 0),
                             max(-c0, 0): self._disc.shape[1] - max(c1 - cols, 0)]

    def update(self) -> None:
        """Account for the step the simulation just took (call once after every step)."""
        sim = self.sim
        dt = sim.sim_time - self._time
        if dt <= 0:
            return
        poses = sim.true_poses
        moved = np.hypot(*(poses[:, :2] - self._poses[:, :2]).T)
        self.distance += moved
        self.stall_events += sim.stalled & ~self._stalled
        away = (np.hypot(*(poses[:, :2] - self._anchors[:, :2]).T) >= STOP_RADIUS) | (
            np.abs((poses[:, 2] - self._anchors[:, 2] + math.pi) % (2 * math.pi) - math.pi) >= STOP_TURN)
        self._anchors[away] = poses[away]
        self._anchor_times[away] = sim.sim_time
        self.longest_stop = np.maximum(self.longest_stop, sim.sim_time - self._anchor_times)
        self._poses, self._stalled, self._time = poses.copy(), sim.stalled.copy(), sim.sim_time
        for robot in range(len(poses)):
            self._stamp(robot)

    def summaries(self, names: list[str] | None = None) -> list[dict]:
        """One JSON-ready summary per robot, in robot order, named ``names`` (default: after the robots' models,
        ``robot_<i>`` for an unnamed one, as the launch scripts print them)."""
        if names is None:
            names = [robot.name or f"robot_{robot.index}" for robot in self.sim.robots]
        free = int(self.free.sum())
        return [
            {
                "robot": name,
                "sim_seconds": round(self._time, 3),
                "distance_m": round(float(self.distance[i]), 2),
                "stall_events": int(self.stall_events[i]),
                "longest_stop_s": round(float(self.longest_stop[i]), 2),
                "coverage": round(float((self.covered[i] & self.free).sum()) / max(free, 1), 4),
            }
            for i, name in enumerate(names)
        ]


def _connected(free: np.ndarray, seeds: list[tuple[int, int]]) -> np.ndarray:
    """The free cells 4-connected to any seed cell (iterative dilation; no SciPy needed)."""
    region = np.zeros_like(free)
    for row, col in seeds:
        if 0 <= row < free.shape[0] and 0 <= col < free.shape[1]:
            region[row, col] = free[row, col]
    while True:
        grown = region.copy()
        grown[1:] |= region[:-1]
        grown[:-1] |= region[1:]
        grown[:, 1:] |= region[:, :-1]
        grown[:, :-1] |= region[:, 1:]
        grown &= free
        if np.array_equal(grown, region):
            return region
        region = grown
