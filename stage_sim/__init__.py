"""stage_sim: a pure-Python re-implementation of Stage's stageros for ROS 2.

Dependencies point one way only, top to bottom (enforced by import-linter, ``.importlinter``)::

    ros                                         ROS entry points and nodes; only ros imports rclpy
    cli                                         ROS-free entry points, and the options every command shares
    envs                                        Gymnasium / PettingZoo environments
    rendering | view | bags                     uses of a running simulation
    runs                                        how a run is paced, driven, measured and stopped
    interface                                   stageros' topics, names, frames, QoS, field values (no rclpy)
    wander                                      the reactive controller (never imports sim)
    sim                                         Simulation: robots, kinematics, odometry, collision
    sensing                                     ray casting on the grid, Stage's walk
    maps                                        the static world rasterised
    worldfile                                   .world/.inc/bitmap/YAML → WorldDescription
    backend                                     kernel settings: numba or numpy, threads, numba's cache

The names below are the public API, imported on first use so that ``import stage_sim`` stays cheap.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

_PUBLIC = {
    "Simulation": "stage_sim.sim.simulation",
    "RobotState": "stage_sim.sim.simulation",
    "Scan": "stage_sim.sim.rangers",
    "load_world": "stage_sim.worldfile.loader",
    "load_world_text": "stage_sim.worldfile.loader",
    "WorldDescription": "stage_sim.worldfile.description",
    "WorldError": "stage_sim.worldfile.errors",
    "render": "stage_sim.rendering.frame",
}

__all__ = [
    "RobotState", "Scan", "Simulation", "WorldDescription", "WorldError", "load_world", "load_world_text", "render",
]

if TYPE_CHECKING:
    from stage_sim.rendering.frame import render
    from stage_sim.sim.rangers import Scan
    from stage_sim.sim.simulation import RobotState, Simulation
    from stage_sim.worldfile.description import WorldDescription
    from stage_sim.worldfile.errors import WorldError
    from stage_sim.worldfile.loader import load_world, load_world_text


def __getattr__(name: str) -> Any:
    """PEP 562: import the module behind a public name when it is first asked for."""
    if name not in _PUBLIC:
        raise AttributeError(f"module 'stage_sim' has no attribute {name!r}")
    return getattr(importlib.import_module(_PUBLIC[name]), name)
