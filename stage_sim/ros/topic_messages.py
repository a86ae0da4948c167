"""The rclpy message of every topic in the interface registry (:mod:`stage_sim.interface.topics`).

Per topic: how its message is built once (everything that never changes: frames, scan geometry) and how a
publication's values fill it. The node keeps one built message per endpoint and refills it before publishing:
publishing serialises, so reuse is safe, and nothing is allocated per step.
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from typing import Any

from builtin_interfaces.msg import Time
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Bool
from tf2_msgs.msg import TFMessage

from stage_sim.interface import frames, topics
from stage_sim.interface.fields import LatestScans
from stage_sim.interface.names import RobotNames
from stage_sim.interface.topics import Endpoint, Topic, TopicMessage
from stage_sim.ros import conversions
from stage_sim.sim.simulation import Simulation


def message_class(topic: Topic) -> type:
    """The rclpy message class of a topic's type name (``nav_msgs/msg/Odometry`` → ``nav_msgs.msg.Odometry``)."""
    package, kind, name = topic.msgtype.split("/")
    return getattr(importlib.import_module(f"{package}.{kind}"), name)


def _fill_clock(msg: Clock, sim_time_us: int, endpoint: Endpoint, time: Time) -> Clock:
    msg.clock = time
    return msg


def _build_odometry(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> Odometry:
    robot = names[endpoint.robot]
    return conversions.odometry_msg(robot.odom_frame, robot.base_footprint)


def _build_ground_truth(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> Odometry:
    return conversions.odometry_msg(frames.WORLD_FRAME, names[endpoint.robot].base_footprint)


def _fill_odometry(msg: Odometry, values: tuple[Any, Any], endpoint: Endpoint, time: Time) -> Odometry:
    poses, velocities = values
    return conversions.fill_odometry(msg, poses[endpoint.robot], velocities[endpoint.robot], time)


def _fill_stall(msg: Bool, stalled: Any, endpoint: Endpoint, time: Time) -> Bool:
    msg.data = bool(stalled[endpoint.robot])
    return msg


def _build_scan(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> Any:
    ranger = sim.robots[endpoint.robot].rangers[endpoint.ranger]
    return conversions.scan_msg(ranger, names[endpoint.robot].laser_frames[endpoint.ranger])


def _fill_scan(msg: Any, scans: LatestScans, endpoint: Endpoint, time: Time) -> Any:
    scan = scans.measured(endpoint.robot, endpoint.ranger)
    return None if scan is None else conversions.fill_scan(msg, scan, time)


def _build_tf(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> TFMessage:
    """One transform per robot, refilled in place each step."""
    start = conversions.stamp(0)
    return TFMessage(transforms=[conversions.edge_transform(frames.odometry_edge(n), start) for n in names])


def _fill_tf(msg: TFMessage, odometry_poses: Any, endpoint: Endpoint, time: Time) -> TFMessage:
    for transform, pose in zip(msg.transforms, odometry_poses, strict=True):
        conversions.fill_planar_transform(transform, pose[0], pose[1], pose[2], time)
    return msg


def _fill_tf_static(msg: TFMessage, edges: list[frames.Edge], endpoint: Endpoint, time: Time) -> TFMessage:
    msg.transforms = [conversions.edge_transform(edge, time) for edge in edges]
    return msg


def _fill_map(msg: OccupancyGridMsg, grid: Any, endpoint: Endpoint, time: Time) -> OccupancyGridMsg:
    return conversions.occupancy_grid_msg(grid, frames.WORLD_FRAME, time)


def _empty(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> Any:
    return message_class(endpoint.topic)()


TOPIC_MESSAGES: dict[Topic, TopicMessage] = {
    topics.CLOCK: TopicMessage(_empty, _fill_clock),
    topics.ODOM: TopicMessage(_build_odometry, _fill_odometry),
    topics.GROUND_TRUTH: TopicMessage(_build_ground_truth, _fill_odometry),
    topics.STALL: TopicMessage(_empty, _fill_stall),
    topics.SCAN: TopicMessage(_build_scan, _fill_scan),
    topics.TF: TopicMessage(_build_tf, _fill_tf),
    topics.TF_STATIC: TopicMessage(_empty, _fill_tf_static),
    topics.MAP: TopicMessage(_empty, _fill_map),
}
"""The message of every topic stageros publishes (a test holds this to :data:`topics.PUBLISHED`)."""
