"""Proof that the ROS 2 environment is real: messages, TF, services, and colcon installing the package."""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from builtin_interfaces.msg import Time
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty
from tf2_msgs.msg import TFMessage

from tests.ros.helpers import spin_until

REPO = Path(__file__).resolve().parents[2]


def _scan() -> LaserScan:
    msg = LaserScan()
    msg.header.frame_id = "base_laser_link"
    msg.header.stamp = Time(sec=3, nanosec=100_000_000)
    msg.angle_min, msg.angle_max = -2.0, 2.0
    msg.angle_increment = 4.0 / 239
    msg.range_min, msg.range_max = 0.0, 5.6
    msg.ranges = [1.5] * 240
    msg.intensities = [1.0] * 240
    return msg


def _odom() -> Odometry:
    msg = Odometry()
    msg.header.frame_id = "odom"
    msg.child_frame_id = "base_footprint"
    msg.pose.pose.position.x = 11.1
    msg.pose.pose.orientation.z = math.sin(math.pi / 4)
    msg.pose.pose.orientation.w = math.cos(math.pi / 4)
    msg.twist.twist.linear.x = 0.5
    return msg


def _tf() -> TFMessage:
    t = TransformStamped()
    t.header.frame_id = "odom"
    t.child_frame_id = "base_footprint"
    t.transform.translation.x = 1.25
    t.transform.rotation.w = 1.0
    return TFMessage(transforms=[t])


@pytest.mark.parametrize(
    ("msg_type", "topic", "make", "check"),
    [
        (LaserScan, "base_scan", _scan, lambda m: len(m.ranges) == 240 and m.range_max == pytest.approx(5.6)
         and m.header.frame_id == "base_laser_link" and m.header.stamp.nanosec == 100_000_000),
        (Odometry, "odom", _odom, lambda m: m.pose.pose.position.x == pytest.approx(11.1)
         and m.child_frame_id == "base_footprint" and m.twist.twist.linear.x == pytest.approx(0.5)),
        (Clock, "/clock", lambda: Clock(clock=Time(sec=7, nanosec=5)),
         lambda m: (m.clock.sec, m.clock.nanosec) == (7, 5)),
        (TFMessage, "/tf", _tf, lambda m: m.transforms[0].child_frame_id == "base_footprint"
         and m.transforms[0].transform.translation.x == pytest.approx(1.25)),
    ],
    ids=["LaserScan", "Odometry", "Clock", "TFMessage"],
)
def test_publish_and_receive(ros_context, executor, msg_type, topic, make, check) -> None:
    talker = Node("talker", context=ros_context)
    listener = Node("listener", context=ros_context)
    executor.add_node(talker)
    executor.add_node(listener)
    received: list = []
    listener.create_subscription(msg_type, topic, received.append, 10)
    pub = talker.create_publisher(msg_type, topic, 10)
    assert spin_until(executor, lambda: pub.get_subscription_count() > 0)
    pub.publish(make())
    assert spin_until(executor, lambda: bool(received))
    assert check(received[0])


def test_empty_service_round_trip(ros_context, executor) -> None:
    server = Node("server", context=ros_context)
    client_node = Node("client", context=ros_context)
    executor.add_node(server)
    executor.add_node(client_node)
    calls: list[int] = []

    def handle(request: Empty.Request, response: Empty.Response) -> Empty.Response:
        calls.append(1)
        return response

    server.create_service(Empty, "reset_positions", handle)
    client = client_node.create_client(Empty, "reset_positions")
    assert spin_until(executor, client.service_is_ready)
    future = client.call_async(Empty.Request())
    executor.spin_until_future_complete(future, timeout_sec=5.0)
    assert future.done() and isinstance(future.result(), Empty.Response)
    assert calls == [1]


@pytest.mark.slow
def test_colcon_build_installs_ros2_run_layout(tmp_path: Path) -> None:
    """`colcon build` puts the executables where `ros2 run stage_sim <exe>` looks for them."""
    colcon = Path(sys.executable).with_name("colcon")
    if not colcon.exists():
        colcon = Path(shutil.which("colcon") or "colcon")
    src = tmp_path / "src" / "stage_sim"
    ignore = shutil.ignore_patterns(".venv", ".git", "build", "install", "log", "__pycache__", "*.egg-info",
                                    ".pytest_cache", ".ruff_cache")
    shutil.copytree(REPO, src, ignore=ignore)
    result = subprocess.run(
        [str(colcon), "build", "--base-paths", "src"],
        cwd=tmp_path, capture_output=True, text=True, timeout=300, env=dict(os.environ),
    )
    assert result.returncode == 0, result.stdout + result.stderr
    install = tmp_path / "install"
    exe_dir = install / "stage_sim" / "lib" / "stage_sim"
    scripts = sorted(p.name for p in exe_dir.iterdir())
    for exe in ("stage_sim", "stageros", "teleop", "wander"):
        assert exe in scripts, scripts
        assert os.access(exe_dir / exe, os.X_OK)
    assert (install / "stage_sim" / "share" / "stage_sim" / "package.xml").is_file()
    assert (install / "stage_sim" / "share" / "ament_index" / "resource_index" / "packages" / "stage_sim").is_file()
