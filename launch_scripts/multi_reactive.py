#!/usr/bin/env python3
"""Several robots, each with its own wanderer in its ``robot_<i>`` namespace, in one process.

``python launch_scripts/multi_reactive.py [WORLD] [--speedup X] [--duration S] [--seed N] [--record OUT]
[--bag OUT.mcap]`` runs the world (default ``multi_robots.world``) until ``--duration`` sim seconds, the world's
``quit_time`` or Ctrl-C, then prints one JSON summary per robot: sim_seconds, distance_m, stall_events (other
robots included), longest_stop_s, coverage. ``--bag`` records every topic stageros publishes into a ROS 2 bag (MCAP).
``--speedup 0`` runs in lockstep as fast as possible, reproducibly for a given ``--seed``.
"""

import os
import sys
from pathlib import Path

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

from stage_sim.ros.session import wander_main

if __name__ == "__main__":
    sys.exit(wander_main(sys.argv[1:], "multi_reactive.py", "multi_robots.world", __doc__.splitlines()[0]))
