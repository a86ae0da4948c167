"""The QoS profiles of stageros' interface as plain data, each declared once.

:mod:`stage_sim.ros.qos` turns them into rclpy's ``QoSProfile`` and :mod:`stage_sim.bags.topics` into the
profiles a bag offers on replay. Deadline, lifespan and liveliness stay at the ROS defaults everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


class Reliability(Enum):
    RELIABLE = "reliable"
    BEST_EFFORT = "best_effort"


class Durability(Enum):
    VOLATILE = "volatile"
    TRANSIENT_LOCAL = "transient_local"


class History(Enum):
    KEEP_LAST = "keep_last"
    KEEP_ALL = "keep_all"


@dataclass(frozen=True)
class Qos:
    """One QoS profile: the policies stageros and its controllers set."""

    depth: int
    reliability: Reliability = Reliability.RELIABLE
    durability: Durability = Durability.VOLATILE
    history: History = History.KEEP_LAST


RELIABLE_10 = Qos(depth=10)
"""/clock, odometry, ground truth, stall, scans and cmd_vel."""
TF_STREAM = Qos(depth=100)
"""/tf: a step's transforms must not push out those a listener has not read yet."""
LATCHED = Qos(depth=1, durability=Durability.TRANSIENT_LOCAL)
"""/tf_static and /map: sent once, kept for late joiners."""
NEWEST_ONLY = Qos(depth=1)
"""The wanderer's scans: a backlog (a slow start, a loaded machine) would replay stale scans, each answered
with a command for where the robot no longer is."""
EVERY_REQUEST = Qos(depth=10, history=History.KEEP_ALL)
"""Services: every request is a caller waiting for its answer; keeping the last 10 drops requests whenever
the executor lags (numba loading on its thread, a command flood), and those callers hang forever."""
