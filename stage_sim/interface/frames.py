"""The frames of stageros' TF tree: the world frame and the fixed edges /tf_static carries.

Per-robot frame names (``odom``, ``base_footprint``, ``base_link``, ``base_laser_link[_k]``) follow the name
rules of :mod:`stage_sim.interface.names`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from stage_sim.interface.names import RobotNames

if TYPE_CHECKING:
    from stage_sim.sim.robots import RobotSpec

WORLD_FRAME = "world"
"""The frame of ground truth and /map."""


@dataclass(frozen=True)
class Edge:
    """One TF edge ``parent → child`` at (x, y, z, yaw)."""

    parent: str
    child: str
    x: float
    y: float
    z: float
    yaw: float


def odometry_edge(names: RobotNames) -> Edge:
    """The moving edge ``odom → base_footprint`` of one robot (/tf, every step), at its origin."""
    return Edge(names.odom_frame, names.base_footprint, 0.0, 0.0, 0.0, 0.0)


def static_edges(robots: list[RobotSpec], names: list[RobotNames]) -> list[Edge]:
    """Every fixed frame of every robot, as /tf_static carries them in one latched message:
    ``base_footprint → base_link`` (identity) and ``base_link → base_laser_link[_k]`` (the ranger's pose,
    z already including the robot height)."""
    edges = []
    for robot, robot_names in zip(robots, names, strict=True):
        edges.append(Edge(robot_names.base_footprint, robot_names.base_link, 0.0, 0.0, 0.0, 0.0))
        for ranger, frame in zip(robot.rangers, robot_names.laser_frames, strict=True):
            pose = ranger.pose
            edges.append(Edge(robot_names.base_link, frame, pose.x, pose.y, pose.z, pose.yaw))
    return edges
