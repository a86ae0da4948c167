"""Load a world, drive every robot for 10 steps (1 s at Stage's default interval) and print one JSON line.

The corpus tests run it in a child process with capped memory, so a world whose raster would eat the
machine fails there instead of inside pytest.
"""

from __future__ import annotations

import json
import re
import sys
from collections import Counter

import numpy as np

from stage_sim import Simulation, load_world
from stage_sim.worldfile.loader import NOT_SIMULATED

STEPS = 10
FORWARD, SIDEWAYS, TURN = 0.3, 0.2, 0.5
NOT_SIMULATED_WARNING = re.compile(r"^'(\w+)' models are not simulated")


def drive(path: str) -> dict:
    """What a user would check after a second of driving: finite poses and scans, every robot moved or stalled."""
    description = load_world(path)
    sim = Simulation(description, seed=1)
    start = sim.true_poses.copy()
    for _ in range(STEPS):
        for index, robot in enumerate(sim.robots):
            sim.set_velocity(index, FORWARD, SIDEWAYS if robot.drive.holonomic else 0.0, TURN)
        sim.step()
    scans = [scan for robot_scans in sim.scans for scan in robot_scans]
    moved = np.any(sim.true_poses != start, axis=1)
    warned = Counter(m.group(1) for w in sim.warnings if (m := NOT_SIMULATED_WARNING.match(w.message)))
    return {
        "steps": round(sim.sim_time / sim.interval),
        "robots": len(sim.robots),
        "finite_poses": bool(np.isfinite(sim.true_poses).all() and np.isfinite(sim.odometry_poses).all()),
        "scans": len(scans),
        "finite_scans": all(bool(np.isfinite(s.ranges).all() and np.isfinite(s.intensities).all()) for s in scans),
        "neither_moved_nor_stalled": [r.name for r, m, s in zip(sim.robots, moved, sim.stalled, strict=True)
                                      if not m and not s],
        "unsupported_types": sorted({m.type for m in description.walk() if m.type in NOT_SIMULATED}),
        "unsupported_type_warnings": dict(warned),
    }


if __name__ == "__main__":
    print(json.dumps(drive(sys.argv[1])))
