"""stageros' messages built from a simulation's state with rosbags' message classes, serialised to CDR.

rosbags rather than mcap-ros2-support: its type store ships the Jazzy definitions (no .msg files, no ROS),
generates the ros2msg schema text and RIHS01 type hashes rosbag2 records, and serialises numpy arrays
without a Python loop per element (about 10 µs for a 240-beam scan).

The stepping thread only takes a :class:`StepState` (a few array copies); the messages are made on the bag's
writer thread. The topics and their values come from the interface registry (:mod:`stage_sim.interface.topics`),
the one the ROS layer publishes from; this module holds one message filler per topic, as
:mod:`stage_sim.ros.topic_messages` does for rclpy. The latched messages are filled and serialised by rosbags;
the per-step ones are serialised by rosbags once per endpoint (:func:`template`) and then refilled in those
bytes (:mod:`stage_sim.bags.layouts`), which costs a fraction of a serialisation.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_typestore

from stage_sim.bags.layouts import BoolLayout, ClockLayout, Layout, OdometryLayout, ScanLayout, TransformsLayout
from stage_sim.bags.topics import Topic as RecordedTopic
from stage_sim.interface import fields, frames, topics
from stage_sim.interface.names import RobotNames
from stage_sim.interface.topics import Endpoint, Timing, Topic, TopicMessage
from stage_sim.sim.simulation import Simulation

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
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


def _owned(value: Any) -> Any:
    """A topic's values, safe to keep while the simulation steps on (arrays copied, scans snapshotted)."""
    if isinstance(value, np.ndarray):
        return value.copy()
    if isinstance(value, tuple):
        return tuple(_owned(v) for v in value)
    if isinstance(value, fields.LatestScans):
        return value.snapshot()
    return value


@dataclass(frozen=True)
class StepState:
    """What one step publishes, copied off the simulation so the writer thread can build it later."""

    sim_time_us: int
    values: list[Any]
    """The values (:attr:`Topic.values`) of the per-step topics it was captured for, in their order (a list,
    not a dict by topic: hashing a Topic, a dataclass of enums, every step cost more than the copies)."""

    @classmethod
    def capture(cls, sim: Simulation, names: Sequence[RobotNames], stepped: Sequence[Topic]) -> StepState:
        """Copy the state of the step just taken (cheap: small arrays and references to the fresh scans)."""
        return cls(sim.sim_time_us, [_owned(topic.values(sim, names)) for topic in stepped])


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


@dataclass
class _Channel:
    """One interface topic in the bag and, per recorded endpoint, its bag topic, message maker and endpoint:
    a :class:`Layout` for the per-step topics, the built rosbags message for the latched ones."""

    topic: Topic
    outlets: list[tuple[str, Any, Endpoint]]
    prepare: Callable[[Any], Any] | None = None
    """The per-step topics' :meth:`Layout.prepare`."""


class MessageBuilder:
    """Turns a simulation's states into (topic, log time ns, CDR bytes) as stageros would publish them,
    for the ``recorded`` topics only."""

    def __init__(self, sim: Simulation, names: Sequence[RobotNames], recorded: list[RecordedTopic]) -> None:
        self._names = names
        self._channels: list[_Channel] = []
        for topic in topics.PUBLISHED:
            endpoints = [(r.name, r.endpoint) for r in recorded if r.endpoint.topic is topic]
            if not endpoints:
                continue
            if topic.timing is Timing.START:
                outlets = [(name, TOPIC_MESSAGES[topic].build(e, sim, names), e) for name, e in endpoints]
                self._channels.append(_Channel(topic, outlets))
            else:
                outlets = [(name, LAYOUTS[topic](template(topic, e, sim, names)), e) for name, e in endpoints]
                self._channels.append(_Channel(topic, outlets, LAYOUTS[topic].prepare))
        self._stepped = [c for c in self._channels if c.topic.timing is not Timing.START]
        self.stepped = [c.topic for c in self._stepped]
        """The recorded topics published every step: what :meth:`StepState.capture` takes, in this order."""

    def static(self, sim: Simulation) -> Iterator[tuple[str, int, bytes]]:
        """The latched messages stageros sends once at start: /tf_static, and /map when recorded."""
        time = _time(sim.sim_time_us)
        log_time = fields.stamp_ns(sim.sim_time_us)
        for channel in self._channels:
            if channel.topic.timing is Timing.START:
                fill, values = TOPIC_MESSAGES[channel.topic].fill, channel.topic.values(sim, self._names)
                for name, msg, endpoint in channel.outlets:
                    data = TYPESTORE.serialize_cdr(fill(msg, values, endpoint, time), channel.topic.msgtype)
                    yield name, log_time, bytes(data)

    def step(self, state: StepState) -> Iterator[tuple[str, int, bytes]]:
        """Everything one step publishes on the recorded topics, in stageros' publishing order."""
        sim_time_us = state.sim_time_us
        log_time = fields.stamp_ns(sim_time_us)
        for channel, values in zip(self._stepped, state.values, strict=True):
            values = channel.prepare(values)
            for name, layout, endpoint in channel.outlets:
                data = layout.refill(values, endpoint, sim_time_us)
                if data is not None:
                    yield name, log_time, data

    def publications(self, state: StepState) -> int:
        """How many messages :meth:`step` makes of ``state`` (without building them)."""
        count = 0
        for channel, values in zip(self._stepped, state.values, strict=True):
            if channel.topic.timing is Timing.STEP:
                count += len(channel.outlets)
            else:
                count += sum(values.measured(e.robot, e.ranger) is not None for _, _, e in channel.outlets)
        return count
