"""``wander [--ros-args ...]``: a reactive wanderer that never stops, never collides and explores the map.

Subscribes ``base_scan``, ``odom`` and ``stall`` (relative, so a namespace selects the robot) and publishes one
``geometry_msgs/Twist`` on ``cmd_vel`` per scan, decided by :class:`stage_sim.wander.reactive.Wanderer`
(see there for the strategy). Each scan is paired with the odometry of the same stamp, so the remembered
obstacle points behind the robot stay where they were; a ``stall`` (std_msgs/Bool, stageros publishes it every
step before the scans) that was true at any time since the last scan tells the wanderer that its last command
ran the body into something its laser did not show (so a stall is never lost, should the next step's flag
come in before the scan it belongs with). The laser's mounting comes from ``/tf_static``
(parameter ``laser_pose`` until it has arrived). Parameters: ``forward_speed`` (m/s), ``safety_distance`` (m),
``turn_rate`` (rad/s), ``holonomic`` (omni drive), ``seed`` (-1: random), ``footprint`` (the body as
rectangles, flattened ``[x_min, x_max, y_min, y_max, ...]``), ``laser_pose`` ``[x, y, yaw]``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections import deque
from typing import Any

# Project rule: discovery stays on loopback unless the user chose otherwise (set before rclpy loads).
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import numpy as np
import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool
from tf2_msgs.msg import TFMessage

from stage_sim.interface.qos import NEWEST_ONLY
from stage_sim.interface.topics import CMD_VEL, ODOM, SCAN, STALL, TF_STATIC
from stage_sim.ros.parameters import ParameterSpec, ParameterTypeError, declare_parameters
from stage_sim.ros.qos import qos_profile
from stage_sim.runs.interrupts import stop_requests
from stage_sim.wander.config import WanderConfig
from stage_sim.wander.laser_reading import LaserReading
from stage_sim.wander.reactive import Wanderer

ODOM_KEPT = 50  # recent odometry messages kept for pairing with scans by stamp
NO_SCAN_WARNING_S = 5.0  # wall seconds without a scan before the console script says what it is missing


def _nanoseconds(stamp: Any) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def _yaw(q: Any) -> float:
    """Yaw of a quaternion (the rotation about z; roll and pitch are zero here)."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class Wander(Node):
    """Drives one robot with a :class:`Wanderer`; ``kwargs`` go to :class:`rclpy.node.Node`."""

    def __init__(self, node_name: str = "wander", **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        defaults = WanderConfig()
        params = declare_parameters(self, [
            ParameterSpec("seed", -1, "seed of the wanderer's random choices (-1: random)"),
            ParameterSpec("forward_speed", defaults.forward_speed, "cruising speed, m/s"),
            ParameterSpec("safety_distance", defaults.safety_distance, "clearance kept from obstacles, m"),
            ParameterSpec("turn_rate", defaults.turn_rate, "turning speed, rad/s"),
            ParameterSpec("holonomic", defaults.holonomic, "the robot can move sideways (omni drive)"),
            ParameterSpec("footprint", [float(v) for box in defaults.footprint for v in box],
                          "the body as rectangles, flattened [x_min, x_max, y_min, y_max, ...]"),
            ParameterSpec("laser_pose", [0.23, 0.0, 0.0], "[x, y, yaw] of the laser until /tf_static gives it"),
        ])
        seed = params["seed"]
        config = WanderConfig(
            forward_speed=params["forward_speed"], safety_distance=params["safety_distance"],
            turn_rate=params["turn_rate"], holonomic=params["holonomic"],
            footprint=tuple(np.reshape(params["footprint"], (-1, 4)).tolist()),
        )
        self.default_laser_pose = tuple(params["laser_pose"])
        self.wanderer = Wanderer(config, seed=None if seed < 0 else seed)
        self.laser_poses: dict[str, tuple[float, float, float]] = {}  # frame -> pose on the robot, from /tf_static
        self._odometry: deque[tuple[int, tuple[float, float, float]]] = deque(maxlen=ODOM_KEPT)
        self._pending: LaserScan | None = None  # a scan waiting for the odometry of its stamp
        self._stalled = False  # whether a stall was reported since the last decision
        self.decisions = 0  # commands published so far
        self.publisher = self.create_publisher(Twist, CMD_VEL.name, qos_profile(CMD_VEL.qos))
        # Created first: when a step's stall and scan are both waiting, the executor takes the stall first.
        self.create_subscription(Bool, STALL.name, self.on_stall, qos_profile(STALL.qos))
        # Only the newest scan matters (not the depth stageros offers): see NEWEST_ONLY.
        self.create_subscription(LaserScan, SCAN.name, self.on_scan, qos_profile(NEWEST_ONLY))
        self.create_subscription(Odometry, ODOM.name, self.on_odom, qos_profile(ODOM.qos))
        self.create_subscription(TFMessage, TF_STATIC.name, self.on_tf_static, qos_profile(TF_STATIC.qos))

    def on_tf_static(self, msg: TFMessage) -> None:
        """Remember where every statically mounted frame sits (the scan's frame among them)."""
        for transform in msg.transforms:
            t = transform.transform
            self.laser_poses[transform.child_frame_id] = (t.translation.x, t.translation.y, _yaw(t.rotation))

    def on_stall(self, msg: Bool) -> None:
        self._stalled = self._stalled or bool(msg.data)

    def on_odom(self, msg: Odometry) -> None:
        p = msg.pose.pose
        self._odometry.append((_nanoseconds(msg.header.stamp), (p.position.x, p.position.y, _yaw(p.orientation))))
        if self._pending is not None and _nanoseconds(self._pending.header.stamp) == self._odometry[-1][0]:
            scan, self._pending = self._pending, None
            self.decide(scan, self._odometry[-1][1])

    def on_scan(self, msg: LaserScan) -> None:
        """Answer at once when the odometry of the scan's stamp is in, else when it comes."""
        stamp = _nanoseconds(msg.header.stamp)
        pose = next((pose for t, pose in reversed(self._odometry) if t == stamp), None)
        if pose is not None or not self._odometry:  # no odometry at all: the wanderer dead-reckons
            self.decide(msg, pose)
        else:
            if self._pending is not None:  # its odometry never came: use the latest rather than skip it
                self.decide(self._pending, self._odometry[-1][1])
            self._pending = msg

    def decide(self, scan: LaserScan, pose: tuple[float, float, float] | None) -> None:
        """Publish the wanderer's command for one scan."""
        reading = LaserReading(
            np.asarray(scan.ranges, dtype=np.float64), scan.angle_min, scan.angle_increment, scan.range_min,
            scan.range_max, self.laser_poses.get(scan.header.frame_id, self.default_laser_pose))
        vx, vy, wz = self.wanderer.decide(reading, _nanoseconds(scan.header.stamp) / 1e9, pose, self._stalled)
        self._stalled = False
        self.decisions += 1
        msg = Twist()
        msg.linear.x, msg.linear.y, msg.angular.z = vx, vy, wz
        self.publisher.publish(msg)

    def stop(self) -> None:
        """Publish a zero twist (on the way out: the robot must not keep the last command)."""
        if self.context.ok():
            self.publisher.publish(Twist())


def parse_args(argv: list[str]) -> argparse.Namespace:
    """``--help`` (and a clear error for anything else that is not a ROS argument)."""
    parser = argparse.ArgumentParser(
        prog="wander", description="A reactive wanderer: drives one robot from its laser scans without "
        "stopping or colliding, and explores the map. Subscribes base_scan, odom, stall and /tf_static; "
        "publishes cmd_vel (relative names: a namespace, e.g. --ros-args -r __ns:=/robot_0, picks the robot).",
        epilog="parameters (--ros-args -p NAME:=VALUE): forward_speed (m/s), safety_distance (m), turn_rate "
        "(rad/s), holonomic (omni drive), seed (-1: random), footprint [x_min, x_max, y_min, y_max, ...], "
        "laser_pose [x, y, yaw] (until /tf_static gives it)")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Run the wanderer until Ctrl-C, SIGTERM or shutdown, then stop the robot; returns the exit status."""
    argv = list(sys.argv if argv is None else argv)
    parse_args(remove_ros_args(argv)[1:])
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    node = None
    try:
        with stop_requests() as stop:
            node = Wander()
            scans, commands = node.resolve_topic_name(SCAN.name), node.resolve_topic_name(CMD_VEL.name)
            node.get_logger().info(f"waiting for scans on {scans}; commands go to {commands}")
            executor = SingleThreadedExecutor()
            executor.add_node(node)
            started, warned = time.monotonic(), False
            while not stop.is_set():
                executor.spin_once(timeout_sec=0.1)
                if not warned and node.decisions == 0 and time.monotonic() - started > NO_SCAN_WARNING_S:
                    warned = True
                    node.get_logger().warning(
                        f"no scan on {scans} after {NO_SCAN_WARNING_S:g} s: is stageros running, on the same "
                        f"ROS_DOMAIN_ID ({os.environ.get('ROS_DOMAIN_ID', '0')}), with this robot's namespace?")
        return 0
    except ParameterTypeError as error:
        print(f"wander: {error}", file=sys.stderr)
        return 2
    except ExternalShutdownException:
        return 0
    finally:
        if node is not None:
            node.stop()
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
