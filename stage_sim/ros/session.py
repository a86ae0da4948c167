"""In-process sessions for the launch scripts: the simulator and one wanderer per robot in one executor.

One process and one executor spare the launch machinery and, with ``speedup <= 0``, allow *lockstep*: step
the world, then spin until every wanderer has answered that step's scan with a command the simulator has
received (or a short wall timeout passes), so a seed gives the same run every time. With ``speedup > 0`` a
steady wall timer paces the steps at ``interval_sim / speedup``, as the simulator's own would. Either way
:class:`RunStats` samples the ground truth after every step and gives the JSON summaries printed at exit.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import signal
import sys
import time
from collections.abc import Iterator

import numpy as np
import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions

from stage_sim.core.errors import WorldError
from stage_sim.core.simulation import Simulation
from stage_sim.ros.stageros import StageRos
from stage_sim.ros.wander import Wander

STOP_SPEED = 0.01  # m/s and rad/s below which a robot counts as standing still
LOCKSTEP_TIMEOUT_S = 0.5  # wall seconds to wait for the wanderers' answers before stepping anyway
CONNECT_TIMEOUT_S = 10.0  # wall seconds for the in-process publishers and subscriptions to match


class RunStats:
    """Per-robot distance, stall events, longest stop and coverage, from the ground truth of every step.

    Coverage is the share of the map's free cells (``cell`` m squares whose fine cells are all free, 4-connected
    to a robot's start) that came within ``radius`` of the robot: a disc is stamped on a coarse grid wherever
    the robot enters a new cell.
    """

    def __init__(self, sim: Simulation, cell: float = 0.1, radius: float = 1.0) -> None:
        self.sim = sim
        static = sim.static
        factor = max(1, round(cell / static.resolution))
        self.cell = factor * static.resolution
        self.origin = np.array(static.origin_xy, dtype=np.float64)
        rows, cols = (n // factor for n in static.shape)
        fine = static.occupied[: rows * factor, : cols * factor].reshape(rows, factor, cols, factor)
        starts = [self._cell_of(pose) for pose in sim.true_poses]
        self.free = _connected(~fine.any(axis=(1, 3)), starts)
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
        self._stopped_since = np.full(n, math.nan)
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
        turned = np.abs((poses[:, 2] - self._poses[:, 2] + math.pi) % (2 * math.pi) - math.pi)
        self.distance += moved
        self.stall_events += sim.stalled & ~self._stalled
        still = (moved / dt < STOP_SPEED) & (turned / dt < STOP_SPEED)
        self._stopped_since = np.where(still, np.where(np.isnan(self._stopped_since), self._time,
                                                       self._stopped_since), math.nan)
        stopped_for = np.where(still, sim.sim_time - self._stopped_since, 0.0)
        self.longest_stop = np.maximum(self.longest_stop, stopped_for)
        self._poses, self._stalled, self._time = poses.copy(), sim.stalled.copy(), sim.sim_time
        for robot in range(len(poses)):
            self._stamp(robot)

    def summaries(self, names: list[str]) -> list[dict]:
        """One JSON-ready summary per robot, in robot order."""
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


class WanderSession:
    """A simulator and a wanderer per robot (namespaced like the simulator's topics), in one executor."""

    def __init__(self, world: str, speedup: float, seed: int | None, context: Context | None = None) -> None:
        self.stage = StageRos(world, speedup=speedup, seed=seed, autostep=False, context=context)
        sim = self.stage.sim
        self.wanderers = []
        for index, (robot, names) in enumerate(zip(sim.robots, self.stage.names, strict=True)):
            prefix = names.cmd_vel[: -len("cmd_vel")]
            remap = ["--ros-args", "-r", f"base_scan:={names.scans[0][len(prefix):]}"] if robot.rangers else None
            overrides = [Parameter("holonomic", value=robot.settings.drive == "omni")]
            if seed is not None:
                overrides.append(Parameter("seed", value=seed * 100 + index))
            self.wanderers.append(Wander(
                f"wander_{index}", namespace=prefix.rstrip("/") or None, context=context, cli_args=remap,
                parameter_overrides=overrides))
        self.executor = SingleThreadedExecutor(context=context)
        for node in (self.stage, *self.wanderers):
            self.executor.add_node(node)
        self.stats = RunStats(sim)

    def run(self, duration: float | None = None) -> None:
        """Step until ``duration`` sim seconds, the world's quit_time, or Ctrl-C (KeyboardInterrupt)."""
        self._connect()
        stage, sim = self.stage, self.stage.sim
        if stage.speedup > 0:
            stage.create_timer(sim.interval / stage.speedup, self._step, clock=Clock(clock_type=ClockType.STEADY_TIME))
        while not stage.finished and (duration is None or sim.sim_time < duration - 1e-9):
            if stage.speedup > 0:
                self.executor.spin_once(timeout_sec=0.1)
            else:
                self._step()
                self._await_answers()

    def summaries(self) -> list[dict]:
        """The per-robot JSON summaries, named after the robots' models."""
        return self.stats.summaries([robot.name or f"robot_{robot.index}" for robot in self.stage.sim.robots])

    def close(self) -> None:
        """Stop the robots and destroy every node."""
        for node in (*self.wanderers, self.stage):
            self.executor.remove_node(node)
            node.destroy_node()
        self.executor.shutdown(timeout_sec=1.0)

    def _step(self) -> None:
        self.stage.step_once()
        self.stats.update()

    def _connect(self) -> None:
        """Spin until every scan, odometry and command topic has matched (discovery, even in-process)."""
        stage = self.stage
        deadline = time.monotonic() + CONNECT_TIMEOUT_S
        while time.monotonic() < deadline and not all(
            stage.odom_pubs[i].get_subscription_count() and w.publisher.get_subscription_count()
            and all(p.get_subscription_count() for p in stage.scan_pubs[i][:1])
            for i, w in enumerate(self.wanderers)
        ):
            self.executor.spin_once(timeout_sec=0.01)

    def _await_answers(self) -> None:
        """Lockstep: spin until each robot that got a scan this step has had its command accepted."""
        sim = self.stage.sim
        waiting = [i for i in range(len(self.wanderers)) if any(s.stamp == sim.sim_time for s in sim.scans[i])]
        deadline = time.monotonic() + LOCKSTEP_TIMEOUT_S
        while any(sim.last_command_us[i] != sim.sim_time_us for i in waiting) and time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.01)


@contextlib.contextmanager
def sigterm_interrupts() -> Iterator[None]:
    """Let SIGTERM end a session like Ctrl-C, so the summaries are still printed."""
    previous = signal.signal(signal.SIGTERM, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def parse_args(argv: list[str], prog: str, default_world: str, description: str) -> argparse.Namespace:
    """The launch scripts' common options."""
    parser = argparse.ArgumentParser(prog=prog, description=description)
    parser.add_argument("world", nargs="?", default=default_world,
                        help=f"a .world file or a bundled world's name (default {default_world})")
    parser.add_argument("--speedup", type=float, default=1.0,
                        help="sim seconds per wall second (default 1); <= 0: lockstep, as fast as possible")
    parser.add_argument("--duration", type=float, default=None, help="sim seconds to run (default: until Ctrl-C)")
    parser.add_argument("--seed", type=int, default=None, help="seed of the simulator and the wanderers")
    return parser.parse_args(argv)


def wander_main(argv: list[str], prog: str, default_world: str, description: str) -> int:
    """Run a wander session and print one JSON summary per robot at the end (also after Ctrl-C)."""
    args = parse_args(argv, prog, default_world, description)
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    session = None
    try:
        with sigterm_interrupts():
            session = WanderSession(args.world, args.speedup, args.seed)
            with contextlib.suppress(KeyboardInterrupt):
                session.run(args.duration)
            for summary in session.summaries():
                print(json.dumps(summary), flush=True)
        return 0
    except (WorldError, FileNotFoundError, ValueError) as error:
        print(f"{prog}: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 0
    finally:
        if session is not None:
            session.close()
        rclpy.try_shutdown()
