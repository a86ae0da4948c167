"""What a laser beam reports as intensity: the return of the static cell or the robot it hit, 0 on a miss.

The numpy reference; :mod:`stage_sim.sim.ranger_kernels` is its compiled twin (the same values, bit for bit).
"""

from __future__ import annotations

import numpy as np

from stage_sim.maps.tiles import CellValues
from stage_sim.sensing.robot_layer import SEVERAL_ROBOTS


def hit_intensity(cell: np.ndarray, hit_robot: np.ndarray, static: CellValues, robot_return: np.ndarray,
                  robots_seen: bool, rays: np.ndarray, out: np.ndarray, threads: int = 1) -> None:
    """``out[rays[i]]``: the intensity of ray i, from its hit cell (-1: a miss) and robot (-1: none,
    :data:`~stage_sim.sensing.robot_layer.SEVERAL_ROBOTS`: two or more): the static cell's return, or the robot's
    ``ranger_return`` when ``robots_seen`` (more than one robot). The numpy reference (``threads``: the compiled
    twin's, :func:`stage_sim.sim.compiled.hit_intensity`)."""
    static_hit = (cell >= 0) & (hit_robot == -1)
    hits = np.zeros(len(rays), dtype=np.float32)
    hits[static_hit] = static.at(cell[static_hit])
    if robots_seen:
        robot_hit = hit_robot >= 0
        hits[robot_hit] = robot_return[hit_robot[robot_hit]]
        # A cell two robots share (they touch there) reports no single robot: the brighter one answers.
        hits[hit_robot == SEVERAL_ROBOTS] = robot_return.max(initial=0.0)
    out[rays] = hits
