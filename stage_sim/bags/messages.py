"""stageros' messages built from a simulation's state with rosbags' message classes, serialised to CDR.

rosbags rather than mcap-ros2-support: its type store ships the Jazzy definitions (no .msg files, no ROS),
generates the ros2msg schema text and RIHS01 type hashes rosbag2 records, and serialises numpy arrays
without a Python loop per element (about 10 µs for a 240-beam scan).

The stepping thread only takes a :class:`StepState` (a few array copies); building and serialising the
messages happens on the bag's writer thread. Field values come from :mod:`stage_sim.bags.fields`, the
description the ROS layer fills its rclpy messages from.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import asdict, dataclass

import numpy as np
from rosbags.typesys import Stores, get_typestore

from stage_sim.bags import fields
from stage_sim.bags.names import RobotNames
from stage_sim.bags.topics import CLOCK, MAP, TF, TF_STATIC, RobotTopics
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.occupancy import OccupancyGrid

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


@dataclass(frozen=True)
class StepState:
    """What one step publishes, copied off the simulation so the writer thread can build it later."""

    sim_time_us: int
    odometry: np.ndarray
    truth: np.ndarray
    velocities: np.ndarray
    truth_velocities: np.ndarray
    stalled: np.ndarray
    scans: tuple[tuple[int, int, np.ndarray, np.ndarray], ...]
    """(robot, ranger, ranges, intensities) of every ranger that measured in this step."""

    @classmethod
    def capture(cls, sim: Simulation) -> StepState:
        """Copy the state of the step just taken (cheap: small arrays and the fresh scans)."""
        return cls(
            sim.sim_time_us, sim.odometry_poses.copy(), sim.true_poses.copy(), sim.velocities.copy(),
            sim.true_velocities, sim.stalled.copy(),
            tuple((i, k, *fields.scan_arrays(scan)) for i, robot_scans in enumerate(sim.scans)
                  for k, scan in enumerate(robot_scans) if fields.is_fresh(scan, sim)),
        )

    @property
    def message_count(self) -> int:
        """Messages this step publishes on every topic: /clock, /tf, odom, truth and stall per robot, scans."""
        return 2 + 3 * len(self.stalled) + len(self.scans)


def _time(sim_time_us: int) -> object:
    sec, nanosec = fields.stamp_parts(sim_time_us)
    return Time(sec=sec, nanosec=nanosec)


def _quaternion(yaw: float) -> object:
    x, y, z, w = fields.yaw_quaternion(float(yaw))
    return Quaternion(x=x, y=y, z=z, w=w)


def _transform(time: object, edge: fields.Edge) -> object:
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


def _fill_odometry(msg: object, time: object, pose: np.ndarray, velocity: np.ndarray) -> object:
    msg.header.stamp = time
    position, orientation = msg.pose.pose.position, msg.pose.pose.orientation
    position.x, position.y = float(pose[0]), float(pose[1])
    _, _, orientation.z, orientation.w = fields.yaw_quaternion(float(pose[2]))
    twist = msg.twist.twist
    twist.linear.x, twist.linear.y, twist.angular.z = float(velocity[0]), float(velocity[1]), float(velocity[2])
    return msg


@dataclass
class _RobotMessages:
    """The messages one robot publishes every step, allocated once and refilled (as the node does)."""

    odom: object
    truth: object
    stall: object
    odom_tf: object
    scans: list[object]


class MessageBuilder:
    """Turns a simulation's states into (topic, log time ns, CDR bytes) as stageros would publish them."""

    def __init__(self, sim: Simulation, names: list[RobotNames], topics: list[RobotTopics]) -> None:
        self.topics = topics
        self.edges = fields.static_edges(sim.robots, names)
        self._out = [
            _RobotMessages(
                odom=_odometry(n.odom_frame, n.base_footprint),
                truth=_odometry(fields.WORLD_FRAME, n.base_footprint),
                stall=Bool(data=False),
                odom_tf=_transform(_time(0), fields.Edge(n.odom_frame, n.base_footprint, 0.0, 0.0, 0.0, 0.0)),
                scans=[LaserScan(header=Header(stamp=_time(0), frame_id=frame), **asdict(fields.scan_geometry(r)),
                                 ranges=np.zeros(0, np.float32), intensities=np.zeros(0, np.float32))
                       for r, frame in zip(robot.rangers, n.laser_frames, strict=True)],
            )
            for robot, n in zip(sim.robots, names, strict=True)
        ]
        self._tf = TFMessage(transforms=[out.odom_tf for out in self._out])

    def static(self, sim_time_us: int, grid: OccupancyGrid | None) -> Iterator[tuple[str, int, bytes]]:
        """The latched messages stageros sends once at start: /tf_static, and /map when asked."""
        time = _time(sim_time_us)
        log_time = fields.stamp_ns(sim_time_us)
        tf = TFMessage(transforms=[_transform(time, edge) for edge in self.edges])
        yield TF_STATIC, log_time, TYPESTORE.serialize_cdr(tf, TFMessage.__msgtype__)
        if grid is not None:
            origin = Pose(position=Point(x=float(grid.origin[0]), y=float(grid.origin[1]), z=0.0),
                          orientation=_quaternion(grid.origin[2]))
            info = MapMetaData(map_load_time=time, resolution=float(grid.resolution), width=grid.width,
                               height=grid.height, origin=origin)
            msg = OccupancyGridMsg(header=Header(stamp=time, frame_id=fields.WORLD_FRAME), info=info,
                                   data=grid.values.astype(np.int8).ravel())
            yield MAP, log_time, TYPESTORE.serialize_cdr(msg, OccupancyGridMsg.__msgtype__)

    def step(self, state: StepState, wanted: set[str]) -> Iterator[tuple[str, int, bytes]]:
        """Everything one step publishes on the ``wanted`` topics, in stageros' publishing order."""
        time = _time(state.sim_time_us)
        log_time = fields.stamp_ns(state.sim_time_us)
        serialize = TYPESTORE.serialize_cdr
        if CLOCK in wanted:
            yield CLOCK, log_time, serialize(Clock(clock=time), Clock.__msgtype__)
        scans: dict[int, list[tuple[int, np.ndarray, np.ndarray]]] = {}
        for robot, ranger, ranges, intensities in state.scans:
            scans.setdefault(robot, []).append((ranger, ranges, intensities))
        for i, (out, topics) in enumerate(zip(self._out, self.topics, strict=True)):
            if topics.odom in wanted:
                msg = _fill_odometry(out.odom, time, state.odometry[i], state.velocities[i])
                yield topics.odom, log_time, serialize(msg, Odometry.__msgtype__)
            if topics.ground_truth in wanted:
                msg = _fill_odometry(out.truth, time, state.truth[i], state.truth_velocities[i])
                yield topics.ground_truth, log_time, serialize(msg, Odometry.__msgtype__)
            if topics.stall in wanted:
                out.stall.data = bool(state.stalled[i])
                yield topics.stall, log_time, serialize(out.stall, Bool.__msgtype__)
            for ranger, ranges, intensities in scans.get(i, ()):
                if topics.scans[ranger] in wanted:
                    msg = out.scans[ranger]
                    msg.header.stamp, msg.ranges, msg.intensities = time, ranges, intensities
                    yield topics.scans[ranger], log_time, serialize(msg, LaserScan.__msgtype__)
        if TF in wanted:
            for out, pose in zip(self._out, state.odometry, strict=True):
                transform = out.odom_tf.transform
                out.odom_tf.header.stamp = time
                transform.translation.x, transform.translation.y = float(pose[0]), float(pose[1])
                _, _, transform.rotation.z, transform.rotation.w = fields.yaw_quaternion(float(pose[2]))
            yield TF, log_time, serialize(self._tf, TFMessage.__msgtype__)
