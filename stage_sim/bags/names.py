"""Topic and frame names per robot, following stageros' rules with tf2-valid frame ids.

One robot (and no ``-u``): plain relative names (``odom``, ``base_scan``). Several robots: ``robot_<i>/``
prefixes in world-file order, or the model's ``name`` with ``use_model_names`` when it is a valid ROS name
(Stage's automatic tokens such as ``position:0`` are not, and fall back to ``robot_<i>``). Several rangers
on one robot: ``base_scan_<k>`` and ``base_laser_link_<k>``. Frame ids never start with ``/`` (stage_ros'
multi-robot frames did, which tf2 rejects). Topics stay relative so they move with a node namespace.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_VALID_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class RobotNames:
    """Every name one robot uses on the ROS graph."""

    cmd_vel: str
    odom: str
    ground_truth: str
    stall: str
    scans: tuple[str, ...]
    odom_frame: str
    base_footprint: str
    base_link: str
    laser_frames: tuple[str, ...]


def robot_prefix(index: int, model_name: str, robot_count: int, use_model_names: bool) -> str:
    """'' for a lone robot, else 'robot_<i>/' or '<model name>/'."""
    if robot_count == 1 and not use_model_names:
        return ""
    if use_model_names and _VALID_NAME.match(model_name):
        return f"{model_name}/"
    return f"robot_{index}/"


def robot_names(
    index: int, model_name: str, robot_count: int, ranger_count: int, use_model_names: bool = False
) -> RobotNames:
    """The names of robot ``index`` given how many robots and rangers the world has."""
    p = robot_prefix(index, model_name, robot_count, use_model_names)
    if ranger_count == 1:
        scans, lasers = ("base_scan",), ("base_laser_link",)
    else:
        scans = tuple(f"base_scan_{k}" for k in range(ranger_count))
        lasers = tuple(f"base_laser_link_{k}" for k in range(ranger_count))
    return RobotNames(
        cmd_vel=f"{p}cmd_vel",
        odom=f"{p}odom",
        ground_truth=f"{p}base_pose_ground_truth",
        stall=f"{p}stall",
        scans=tuple(p + s for s in scans),
        odom_frame=f"{p}odom",
        base_footprint=f"{p}base_footprint",
        base_link=f"{p}base_link",
        laser_frames=tuple(p + f for f in lasers),
    )
