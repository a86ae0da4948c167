"""Pure conversions from simulation state to ROS messages: no node, no publishing, easy to test.

The values come from :mod:`stage_sim.interface.fields`, which the ROS-free bag writer uses too.
"""

from __future__ import annotations

from array import array
from dataclasses import asdict

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Quaternion, TransformStamped
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan

from stage_sim.interface import fields
from stage_sim.interface.frames import Edge
from stage_sim.sim.rangers import Scan
from stage_sim.sim.robots import RangerSpec
from stage_sim.worldfile.occupancy import OccupancyGrid


def stamp(sim_time_us: int) -> Time:
    """builtin_interfaces/Time of a sim time in integer microseconds (exact, no float rounding)."""
    sec, nanosec = fields.stamp_parts(sim_time_us)
    return Time(sec=sec, nanosec=nanosec)


def yaw_quaternion(yaw: float) -> Quaternion:
    """Rotation about z by ``yaw`` radians."""
    x, y, z, w = fields.yaw_quaternion(yaw)
    return Quaternion(x=x, y=y, z=z, w=w)


def scan_msg(ranger: RangerSpec, frame_id: str) -> LaserScan:
    """A LaserScan with everything that never changes for this ranger: CCW from −fov/2, its range limits."""
    msg = LaserScan(**asdict(fields.scan_geometry(ranger)))
    msg.header.frame_id = frame_id
    return msg


def fill_scan(msg: LaserScan, scan: Scan, time: Time) -> LaserScan:
    """Put one measurement into a ranger's message: a miss reads exactly range_max."""
    msg.header.stamp = time
    ranges, intensities = fields.scan_arrays(scan)
    msg.ranges = array("f", ranges.tobytes())
    msg.intensities = array("f", intensities.tobytes())
    return msg


def odometry_msg(frame_id: str, child_frame_id: str) -> Odometry:
    """An Odometry between two frames, covariances 0 (as stageros sends them)."""
    msg = Odometry()
    msg.header.frame_id = frame_id
    msg.child_frame_id = child_frame_id
    return msg


def fill_odometry(msg: Odometry, pose: np.ndarray, velocity: np.ndarray, time: Time) -> Odometry:
    """Pose (x, y, yaw) in the message's frame and body-frame twist (vx, vy, va)."""
    msg.header.stamp = time
    position, orientation = msg.pose.pose.position, msg.pose.pose.orientation
    position.x, position.y = float(pose[0]), float(pose[1])
    _, _, orientation.z, orientation.w = fields.yaw_quaternion(pose[2])
    twist = msg.twist.twist
    twist.linear.x, twist.linear.y, twist.angular.z = float(velocity[0]), float(velocity[1]), float(velocity[2])
    return msg


def fill_planar_transform(t: TransformStamped, x: float, y: float, yaw: float, time: Time) -> TransformStamped:
    """Move a planar TF edge (z = 0) to (x, y, yaw) at ``time``."""
    t.header.stamp = time
    t.transform.translation.x, t.transform.translation.y = float(x), float(y)
    _, _, t.transform.rotation.z, t.transform.rotation.w = fields.yaw_quaternion(yaw)
    return t


def edge_transform(edge: Edge, time: Time) -> TransformStamped:
    """One TF edge ``parent → child`` at ``time``."""
    t = TransformStamped()
    t.header.stamp = time
    t.header.frame_id = edge.parent
    t.child_frame_id = edge.child
    t.transform.translation.x = float(edge.x)
    t.transform.translation.y = float(edge.y)
    t.transform.translation.z = float(edge.z)
    t.transform.rotation = yaw_quaternion(float(edge.yaw))
    return t


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
