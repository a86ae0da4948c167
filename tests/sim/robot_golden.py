"""Golden multi-robot runs recorded from Stage 4.3, replayed on stage_sim.

``tests/data/fidelity/robots`` (copied from the project's ``../shared/fidelity/robots``; its README says how
they were recorded) holds, per world, every robot's first scan with all robots standing at their start
poses (``<world>_scans.jsonl``) and every robot's true pose and stall flag each second while all of them
drive circles at 0.3 m/s, 0.5 rad/s (``<world>_traj.jsonl``). Rows are keyed by start pose: Stage's model
order is not the file's. ``crowd_100_seed11``, ``crowd_1000_seed12`` and ``discs_200_seed13`` are held out:
made by ``tools/held_out_worlds.py`` and recorded the same way, after the rules here were settled.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world

ROBOTS = Path(__file__).resolve().parents[2] / "tests" / "data" / "fidelity" / "robots"
#: The recorded worlds: (name, seconds driven).
WORLDS = {"crowd_100": 30, "crowd_1000": 10, "discs_200": 20, "crowd_100_seed11": 30, "discs_200_seed13": 20,
          "crowd_1000_seed12": 10}
SPEED = (0.3, 0.0, 0.5)
#: A pose closer to Stage's than this is on Stage's path; a range closer than this is identical.
SAME = 1e-3


@dataclass(frozen=True)
class RobotFigures:
    """How close stage_sim is to Stage on one world, as issue #32 measures it."""

    world: str
    robots: int
    scans_identical: float  #: share of beams within 1 mm of Stage's range (robots standing)
    scans_within_1_5_cells: float
    on_path: float  #: share of robots within 1 mm of Stage's pose at the end of the drive
    stalls_differing: int  #: robots whose stall flag at the end differs from Stage's
    seconds: float  #: sim seconds driven

    def as_dict(self) -> dict[str, object]:
        return {k: round(v, 5) if isinstance(v, float) else v for k, v in asdict(self).items()}


def _key(x: float, y: float, yaw_deg: float) -> tuple[float, float]:
    return round(x, 3), round(y, 3)


def _rows(name: str, kind: str, folder: Path = ROBOTS) -> dict[tuple[float, float], dict]:
    with open(folder / f"{name}_{kind}.jsonl") as f:
        rows = [json.loads(line) for line in f]
    return {_key(*(r["pose"] if kind == "scans" else r["start"])): r for r in rows}


def simulation(name: str, kernels: str = "numba", folder: Path = ROBOTS) -> Simulation:
    """The world ``name`` as stage_sim loads it."""
    return Simulation(load_world(folder / f"{name}.world"), seed=1, kernels=kernels)


def robot_keys(sim: Simulation) -> list[tuple[float, float]]:
    """Each robot's key in the recordings (its start position)."""
    return [_key(*start[:2], 0.0) for start in sim.start_poses]


def scan_figures(name: str, sim: Simulation, folder: Path = ROBOTS) -> tuple[float, float]:
    """(identical, within 1.5 cells) shares of beams of the robots' first scans, all robots standing."""
    golden = _rows(name, "scans", folder)
    ours = np.concatenate([sim.scans[i][0].ranges for i in range(len(sim.robots))]).astype(np.float64)
    stage = np.concatenate([golden[k]["stage_ranges"] for k in robot_keys(sim)])
    diff = np.abs(ours - stage)
    resolution = sim.description.settings.resolution
    return float(np.mean(diff < SAME)), float(np.mean(diff <= 1.5 * resolution))


def drive(sim: Simulation, seconds: float) -> None:
    """Every robot driving Stage's circle for ``seconds`` of sim time."""
    for i in range(len(sim.robots)):
        sim.set_velocity(i, *SPEED)
    for _ in range(round(seconds / sim.interval)):
        sim.step()


def trajectory_figures(name: str, sim: Simulation, seconds: float, folder: Path = ROBOTS) -> tuple[float, int]:
    """(share of robots on Stage's path, stall flags differing) after driving ``seconds`` (from the start)."""
    golden = _rows(name, "traj", folder)
    drive(sim, seconds)
    k = round(seconds) - 1
    on_path, stalls = 0, 0
    for i, key in enumerate(robot_keys(sim)):
        row = golden[key]
        x, y = row["pose"][k][:2]
        on_path += bool(np.hypot(sim.true_poses[i, 0] - x, sim.true_poses[i, 1] - y) < SAME)
        stalls += bool(sim.stalled[i]) != bool(row["stall"][k])
    return on_path / len(sim.robots), stalls


def robot_figures(name: str, seconds: float | None = None, kernels: str = "numba",
                  folder: Path = ROBOTS) -> RobotFigures:
    """All figures of world ``name`` in ``folder`` (driven its recorded time unless ``seconds`` says)."""
    seconds = WORLDS[name] if seconds is None else seconds
    sim = simulation(name, kernels, folder)
    identical, within = scan_figures(name, sim, folder)
    on_path, stalls = trajectory_figures(name, sim, seconds, folder)
    return RobotFigures(name, len(sim.robots), identical, within, on_path, stalls, seconds)
