"""The values stageros puts in its messages, computed from a simulation without ROS.

One description serves both writers of those messages: :mod:`stage_sim.ros.conversions` fills rclpy
messages with these values and :mod:`stage_sim.bags.messages` fills the serialisation library's classes
with the same ones, so a bag recorded without ROS holds what stageros publishes, field for field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stage_sim.bags.names import RobotNames
from stage_sim.sim.rangers import Scan
from stage_sim.sim.robots import RangerSpec, RobotSpec
from stage_sim.sim.simulation import Simulation

WORLD_FRAME = "world"
"""The frame of ground truth and /map."""


def stamp_parts(sim_time_us: int) -> tuple[int, int]:
    """(sec, nanosec) of a sim time in integer microseconds: exact, no float rounding."""
    return sim_time_us // 1_000_000, (sim_time_us % 1_000_000) * 1000


def stamp_ns(sim_time_us: int) -> int:
    """A sim time in integer nanoseconds (bag log times)."""
    return sim_time_us * 1000


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation about z by ``yaw`` radians."""
    return 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)


@dataclass(frozen=True)
class ScanGeometry:
    """The LaserScan fields that never change for a ranger: CCW from −fov/2, its range limits."""

    angle_min: float
    angle_max: float
    angle_increment: float
    time_increment: float
    scan_time: float
    range_min: float
    range_max: float


def scan_geometry(ranger: RangerSpec) -> ScanGeometry:
    """A ranger's constant LaserScan fields (one sample: increment 0)."""
    sensor = ranger.sensor
    return ScanGeometry(
        angle_min=-sensor.fov / 2,
        angle_max=sensor.fov / 2,
        angle_increment=sensor.fov / (sensor.samples - 1) if sensor.samples > 1 else 0.0,
        time_increment=0.0,
        scan_time=ranger.update_interval,
        range_min=sensor.range_min,
        range_max=sensor.range_max,
    )


def scan_arrays(scan: Scan) -> tuple[np.ndarray, np.ndarray]:
    """Ranges and intensities as the float32 arrays of a LaserScan (a miss reads exactly range_max)."""
    return scan.ranges.astype(np.float32), scan.intensities.astype(np.float32)


def is_fresh(scan: Scan, sim: Simulation) -> bool:
    """Whether a ranger measured in the step just taken (rangers slower than interval_sim skip steps)."""
    return scan.stamp == sim.sim_time


@dataclass(frozen=True)
class Edge:
    """One TF edge ``parent → child`` at (x, y, z, yaw)."""

    parent: str
    child: str
    x: float
    y: float
    z: float
    yaw: float


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
