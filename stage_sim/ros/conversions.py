"""Pure conversions from simulation state to ROS messages: no node, no publishing, easy to test."""

from __future__ import annotations

import math
from array import array

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Quaternion, TransformStamped
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

from stage_sim.core.occupancy import OccupancyGrid
from stage_sim.core.ranger_sensing import Scan
from stage_sim.core.robot_model import RangerSpec
from stage_sim.core.world_description import Pose


def stamp(sim_time_us: int) -> Time:
    """builtin_interfaces/Time of a sim time in integer microseconds (exact, no float rounding)."""
    return Time(sec=sim_time_us // 1_000_000, nanosec=(sim_time_us % 1_000_000) * 1000)


def clock_msg(sim_time_us: int) -> Clock:
    """The /clock message of one step."""
    return Clock(clock=stamp(sim_time_us))


def yaw_quaternion(yaw: float) -> Quaternion:
    """Rotation about z by ``yaw`` radians."""
    return Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def scan_msg(scan: Scan, ranger: RangerSpec, frame_id: str, time: Time) -> LaserScan:
    """A LaserScan as stageros fills it: CCW from −fov/2, a miss reads exactly range_max."""
    sensor = ranger.sensor
    msg = LaserScan()
    msg.header.stamp = time
    msg.header.frame_id = frame_id
    msg.angle_min = -sensor.fov / 2
    msg.angle_max = sensor.fov / 2
    msg.angle_increment = sensor.fov / (sensor.samples - 1) if sensor.samples > 1 else 0.0
    msg.time_increment = 0.0
    msg.scan_time = ranger.update_interval
    msg.range_min = sensor.range_min
    msg.range_max = sensor.range_max
    msg.ranges = array("f", scan.ranges.astype(np.float32).tobytes())
    msg.intensities = array("f", scan.intensities.astype(np.float32).tobytes())
    return msg


def odometry_msg(
    pose: np.ndarray, velocity: np.ndarray, frame_id: str, child_frame_id: str, time: Time
) -> Odometry:
    """Odometry with pose (x, y, yaw) in ``frame_id`` and body-frame twist (vx, vy, va); covariances 0."""
    msg = Odometry()
    msg.header.stamp = time
    msg.header.frame_id = frame_id
    msg.child_frame_id = child_frame_id
    msg.pose.pose.position.x = float(pose[0])
    msg.pose.pose.position.y = float(pose[1])
    msg.pose.pose.orientation = yaw_quaternion(float(pose[2]))
    msg.twist.twist.linear.x = float(velocity[0])
    msg.twist.twist.linear.y = float(velocity[1])
    msg.twist.twist.angular.z = float(velocity[2])
    return msg


def transform(parent: str, child: str, x: float, y: float, z: float, yaw: float, time: Time) -> TransformStamped:
    """One TF edge ``parent → child``."""
    t = TransformStamped()
    t.header.stamp = time
    t.header.frame_id = parent
    t.child_frame_id = child
    t.transform.translation.x = float(x)
    t.transform.translation.y = float(y)
    t.transform.translation.z = float(z)
    t.transform.rotation = yaw_quaternion(float(yaw))
    return t


def ranger_transform(parent: str, child: str, pose: Pose, time: Time) -> TransformStamped:
    """``base_link → base_laser_link``: the ranger's pose on the robot (z already includes the robot height)."""
    return transform(parent, child, pose.x, pose.y, pose.z, pose.yaw, time)


def occupancy_grid_msg(grid: OccupancyGrid, frame_id: str, time: Time) -> OccupancyGridMsg:
    """nav_msgs/OccupancyGrid of the static world (row-major from the bottom-left cell)."""
    msg = OccupancyGridMsg()
    msg.header.stamp = time
    msg.header.frame_id = frame_id
    msg.info.map_load_time = time
    msg.info.resolution = float(grid.resolution)
    msg.info.width = grid.width
    msg.info.height = grid.height
    msg.info.origin.position.x = float(grid.origin[0])
    msg.info.origin.position.y = float(grid.origin[1])
    msg.info.origin.orientation = yaw_quaternion(float(grid.origin[2]))
    msg.data = array("b", grid.values.astype(np.int8).tobytes())
    return msg
