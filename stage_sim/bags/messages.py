"""stageros' messages built from a simulation's state with rosbags' message classes, serialised to CDR.

rosbags rather than mcap-ros2-support: its type store ships the Jazzy definitions (no .msg files, no ROS),
generates the ros2msg schema text and RIHS01 type hashes rosbag2 records, and serialises numpy arrays
without a Python loop per element (about 10 µs for a 240-beam scan).

The stepping side only copies a step's values (:class:`~stage_sim.bags.step_state.StepBatch`); the
per-step messages are made in the bag's writer process (:mod:`stage_sim.bags.writer`). The topics and their
values come from the interface registry (:mod:`stage_sim.interface.topics`), the one the ROS layer publishes
from; this module holds one message filler per topic, as :mod:`stage_sim.ros.topic_messages` does for rclpy.
The latched messages are filled and serialised by rosbags; the per-step ones are serialised by rosbags once
per endpoint (:func:`template`) and then refilled in those bytes (:mod:`stage_sim.bags.layouts`), which costs
a fraction of a serialisation.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import asdict
from typing import Any

import numpy as np

from stage_sim.bags.container import TYPESTORE
from stage_sim.bags.layouts import BoolLayout, ClockLayout, Layout, OdometryLayout, ScanLayout, TransformsLayout
from stage_sim.bags.step_messages import StepChannel, StepMessages
from stage_sim.bags.topics import Topic as RecordedTopic
from stage_sim.interface import fields, frames, topics
from stage_sim.interface.names import RobotNames
from stage_sim.interface.topics import Endpoint, Timing, Topic, TopicMessage
from stage_sim.sim.simulation import Simulation

_T = TYPESTORE.types
Time, Header = _T["builtin_interfaces/msg/Time"], _T["std_msgs/msg/Header"]
Vector3, Quaternion = _T["geometry_msgs/msg/Vector3"], _T["geometry_msgs/msg/Quaternion"]
Point = _T["geometry_msgs/msg/Point"]
Pose, PoseWithCovariance = _T["geometry_msgs/msg/Pose"], _T["geometry_msgs/msg/PoseWithCovariance"]
Twist, TwistWithCovariance = _T["geometry_msgs/msg/Twist"], _T["geometry_msgs/msg/TwistWithCovariance"]
Transform, TransformStamped = _T["geometry_msgs/msg/Transform"], _T["geometry_msgs/msg/TransformStamped"]
Odometry, LaserScan, Bool = _T["nav_msgs/msg/Odometry"], _T["sensor_msgs/msg/LaserScan"], _T["std_msgs/msg/Bool"]
Clock, TFMessage = _T["rosgraph_msgs/msg/Clock"], _T["tf2_msgs/msg/TFMessage"]
OccupancyGridMsg, MapMetaData = _T["nav_msgs/msg/OccupancyGrid"], _T["nav_msgs/msg/MapMetaData"]

_NO_COVARIANCE = np.zeros(36, dtype=np.float64)


def _time(sim_time_us: int) -> object:
    sec, nanosec = fields.stamp_parts(sim_time_us)
    return Time(sec=sec, nanosec=nanosec)


def _quaternion(yaw: float) -> object:
    x, y, z, w = fields.yaw_quaternion(float(yaw))
    return Quaternion(x=x, y=y, z=z, w=w)


def _transform(time: object, edge: frames.Edge) -> object:
    return TransformStamped(
        header=Header(stamp=time, frame_id=edge.parent), child_frame_id=edge.child,
        transform=Transform(translation=Vector3(x=float(edge.x), y=float(edge.y), z=float(edge.z)),
                            rotation=_quaternion(edge.yaw)))


def _odometry(frame: str, child: str) -> object:
    """An Odometry between two frames, covariances 0 (as stageros sends them), filled by :func:`_fill_odometry`."""
    return Odometry(
        header=Header(stamp=_time(0), frame_id=frame), child_frame_id=child,
        pose=PoseWithCovariance(pose=Pose(position=Point(x=0.0, y=0.0, z=0.0), orientation=_quaternion(0.0)),
                                covariance=_NO_COVARIANCE),
        twist=TwistWithCovariance(
            twist=Twist(linear=Vector3(x=0.0, y=0.0, z=0.0), angular=Vector3(x=0.0, y=0.0, z=0.0)),
            covariance=_NO_COVARIANCE))


def _nothing(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> None:
    """For topics whose message is made whole at each publication."""


def _fill_clock(msg: None, sim_time_us: int, endpoint: Endpoint, time: object) -> object:
    return Clock(clock=time)


def _build_odometry(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> object:
    robot = names[endpoint.robot]
    return _odometry(robot.odom_frame, robot.base_footprint)


def _build_ground_truth(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> object:
    return _odometry(frames.WORLD_FRAME, names[endpoint.robot].base_footprint)


def _fill_odometry(msg: Any, values: tuple[np.ndarray, np.ndarray], endpoint: Endpoint, time: object) -> object:
    poses, velocities = values
    pose, velocity = poses[endpoint.robot], velocities[endpoint.robot]
    msg.header.stamp = time
    position, orientation = msg.pose.pose.position, msg.pose.pose.orientation
    position.x, position.y = float(pose[0]), float(pose[1])
    _, _, orientation.z, orientation.w = fields.yaw_quaternion(float(pose[2]))
    twist = msg.twist.twist
    twist.linear.x, twist.linear.y, twist.angular.z = float(velocity[0]), float(velocity[1]), float(velocity[2])
    return msg


def _build_stall(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> object:
    return Bool(data=False)


def _fill_stall(msg: Any, stalled: np.ndarray, endpoint: Endpoint, time: object) -> object:
    msg.data = bool(stalled[endpoint.robot])
    return msg


def _build_scan(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> object:
    ranger = sim.robots[endpoint.robot].rangers[endpoint.ranger]
    return LaserScan(header=Header(stamp=_time(0), frame_id=names[endpoint.robot].laser_frames[endpoint.ranger]),
                     **asdict(fields.scan_geometry(ranger)),
                     ranges=np.zeros(0, np.float32), intensities=np.zeros(0, np.float32))


def _fill_scan(msg: Any, scans: fields.LatestScans, endpoint: Endpoint, time: object) -> object | None:
    scan = scans.measured(endpoint.robot, endpoint.ranger)
    if scan is None:
        return None
    msg.header.stamp = time
    msg.ranges, msg.intensities = fields.scan_arrays(scan)
    return msg


def _build_tf(endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> object:
    return TFMessage(transforms=[_transform(_time(0), frames.odometry_edge(n)) for n in names])


def _fill_tf(msg: Any, odometry_poses: np.ndarray, endpoint: Endpoint, time: object) -> object:
    for transform_stamped, pose in zip(msg.transforms, odometry_poses, strict=True):
        transform = transform_stamped.transform
        transform_stamped.header.stamp = time
        transform.translation.x, transform.translation.y = float(pose[0]), float(pose[1])
        _, _, transform.rotation.z, transform.rotation.w = fields.yaw_quaternion(float(pose[2]))
    return msg


def _fill_tf_static(msg: None, edges: list[frames.Edge], endpoint: Endpoint, time: object) -> object:
    return TFMessage(transforms=[_transform(time, edge) for edge in edges])


def _fill_map(msg: None, grid: Any, endpoint: Endpoint, time: object) -> object:
    origin = Pose(position=Point(x=float(grid.origin[0]), y=float(grid.origin[1]), z=0.0),
                  orientation=_quaternion(grid.origin[2]))
    info = MapMetaData(map_load_time=time, resolution=float(grid.resolution), width=grid.width,
                       height=grid.height, origin=origin)
    return OccupancyGridMsg(header=Header(stamp=time, frame_id=frames.WORLD_FRAME), info=info,
                            data=grid.values.astype(np.int8).ravel())


TOPIC_MESSAGES: dict[Topic, TopicMessage] = {
    topics.CLOCK: TopicMessage(_nothing, _fill_clock),
    topics.ODOM: TopicMessage(_build_odometry, _fill_odometry),
    topics.GROUND_TRUTH: TopicMessage(_build_ground_truth, _fill_odometry),
    topics.STALL: TopicMessage(_build_stall, _fill_stall),
    topics.SCAN: TopicMessage(_build_scan, _fill_scan),
    topics.TF: TopicMessage(_build_tf, _fill_tf),
    topics.TF_STATIC: TopicMessage(_nothing, _fill_tf_static),
    topics.MAP: TopicMessage(_nothing, _fill_map),
}
"""The message of every topic stageros publishes (a test holds this to :data:`topics.PUBLISHED`)."""


LAYOUTS: dict[Topic, type[Layout]] = {
    topics.CLOCK: ClockLayout, topics.ODOM: OdometryLayout, topics.GROUND_TRUTH: OdometryLayout,
    topics.STALL: BoolLayout, topics.SCAN: ScanLayout, topics.TF: TransformsLayout,
}
"""The CDR layout of every topic published each step (a test holds this to the per-step topics)."""


def template(topic: Topic, endpoint: Endpoint, sim: Simulation, names: Sequence[RobotNames]) -> bytes:
    """An endpoint's message serialised once by rosbags, the bytes its :data:`LAYOUTS` entry refills: built as
    :data:`TOPIC_MESSAGES` builds it, with a scan's ranges and intensities already as many as its beams."""
    message = TOPIC_MESSAGES[topic]
    msg = message.build(endpoint, sim, names)
    if topic is topics.SCAN:
        beams = np.zeros(sim.robots[endpoint.robot].rangers[endpoint.ranger].sensor.samples, np.float32)
        msg.ranges, msg.intensities = beams, beams
    else:
        msg = message.fill(msg, topic.values(sim, names), endpoint, _time(0))
    return bytes(TYPESTORE.serialize_cdr(msg, topic.msgtype))


class MessageBuilder:
    """Turns a simulation into (topic, log time ns, CDR bytes) as stageros would publish them, for the
    ``recorded`` topics only: the latched messages here (:meth:`static`), the per-step ones by
    :attr:`stepping`, which the bag writer process runs."""

    def __init__(self, sim: Simulation, names: Sequence[RobotNames], recorded: list[RecordedTopic]) -> None:
        self._names = names
        self._latched: list[tuple[Topic, list[tuple[str, Any, Endpoint]]]] = []
        channels = []
        for topic in topics.PUBLISHED:
            endpoints = [(r.name, r.endpoint) for r in recorded if r.endpoint.topic is topic]
            if not endpoints:
                continue
            if topic.timing is Timing.START:
                self._latched.append((topic, [(name, TOPIC_MESSAGES[topic].build(e, sim, names), e)
                                              for name, e in endpoints]))
            else:
                chosen = [e for _, e in endpoints]
                layout = LAYOUTS[topic]([template(topic, e, sim, names) for e in chosen], chosen)
                channels.append(StepChannel(topic, [name for name, _ in endpoints], layout))
        self.stepping = StepMessages(channels)
        """The per-step messages: which topics a :class:`~stage_sim.bags.step_state.StepBatch` copies and how
        the writer refills them."""

    def static(self, sim: Simulation) -> Iterator[tuple[str, int, bytes]]:
        """The latched messages stageros sends once at start: /tf_static, and /map when recorded."""
        time = _time(sim.sim_time_us)
        log_time = fields.stamp_ns(sim.sim_time_us)
        for topic, outlets in self._latched:
            fill, values = TOPIC_MESSAGES[topic].fill, topic.values(sim, self._names)
            for name, msg, endpoint in outlets:
                yield name, log_time, bytes(TYPESTORE.serialize_cdr(fill(msg, values, endpoint, time), topic.msgtype))
