"""Child process of test_large_world: load a 1 km × 1 km world at 0.01 m, step it, print what it saw.

Run alone so that its peak RSS is its own: ``python tests/maps/large_world_child.py``.
"""

from __future__ import annotations

import json
import resource
import time

from stage_sim import Simulation, load_world_text

WORLD = """
resolution 0.01
interval_sim 100
define wall model ( color "gray" obstacle_return 1 ranger_return 1 )
wall( name "south" size [1000 0.2 1] pose [500 0.1 0 0] )
wall( name "north" size [1000 0.2 1] pose [500 999.9 0 0] )
wall( name "west" size [0.2 1000 1] pose [0.1 500 0 0] )
wall( name "east" size [0.2 1000 1] pose [999.9 500 0 0] )
wall( name "box" size [2 2 1] pose [501 502 0 0] )
define laser ranger ( sensor( range [0 5] fov 180 samples 181 ) size [0.05 0.05 0.05] )
define bot position ( size [0.4 0.3 0.2] drive "diff" laser( pose [0.1 0 -0.05 0] ) )
bot( name "east_looker" pose [500 500 0 0] )
bot( name "north_looker" pose [501 500 0 90] )
bot( name "corner" pose [1.5 1.5 0 45] )
bot( name "far_corner" pose [998 998 0 180] )
"""


def main() -> None:
    begin = time.perf_counter()
    sim = Simulation(load_world_text(WORLD, "large.world"), seed=0)
    loaded = time.perf_counter() - begin
    sim.set_velocity(2, 0.5, 0.0, 0.0)
    for _ in range(5):
        sim.step()
    print(json.dumps({
        "cells": list(sim.static.shape),
        "load_s": loaded,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "centre_ranges": [float(sim.scans[i][0].ranges[90]) for i in range(len(sim.robots))],
        "corner_moved": float(sim.true_poses[2, 0] - 1.5),
        "stalled": sim.stalled.tolist(),
    }))


if __name__ == "__main__":
    main()
