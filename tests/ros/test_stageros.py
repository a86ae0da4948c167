"""The stageros node in-process: topics, frames, TF, clock, watchdog, reset, stall, names and /map."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from geometry_msgs.msg import Twist
from nav_msgs.msg import OccupancyGrid, Odometry
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool
from std_srvs.srv import Empty
from tf2_msgs.msg import TFMessage

from stage_sim.ros.stageros import StageRos
from tests.ros.helpers import spin_until

LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)

WORLD = """
resolution 0.02
interval_sim 100
define wall model ( color "black" )
wall( size [10 0.02 1] pose [5 0 0 0] )
wall( size [10 0.02 1] pose [5 10 0 0] )
wall( size [0.02 10 1] pose [0 5 0 0] )
wall( size [0.02 10 1] pose [10 5 0 0] )
define laser ranger ( sensor( range [0.05 8] fov 180 samples 181 ) )
define bot position ( size [0.4 0.3 0.2] drive "diff" localization "odom" odom_error [0 0 0 0] {body} )
"""


def write_world(tmp_path: Path, robots: str, body: str = 'laser( pose [0.1 0 -0.1 0] )') -> Path:
    path = tmp_path / "test.world"
    path.write_text(WORLD.format(body=body) + robots)
    return path


class Probe:
    """A node that records everything the simulator publishes on the topics it is asked about."""

    def __init__(self, context, executor) -> None:
        self.node = Node("probe", context=context)
        executor.add_node(self.node)
        self.executor = executor
        self.messages: dict[str, list] = {}

    def listen(self, msg_type, topic: str, qos=100) -> list:
        self.messages[topic] = []
        self.node.create_subscription(msg_type, topic, self.messages[topic].append, qos)
        return self.messages[topic]

    def wait(self, topic: str, count: int = 1, timeout_s: float = 15.0) -> list:  # discovery under load
        assert spin_until(self.executor, lambda: len(self.messages[topic]) >= count, timeout_s), topic
        return self.messages[topic]


def make_sim(context, executor, world: Path, **params) -> StageRos:
    overrides = [Parameter(k, value=v) for k, v in params.items()]
    node = StageRos(str(world), autostep=False, context=context, parameter_overrides=overrides)
    executor.add_node(node)
    return node


def step(executor, sim: StageRos, probe: Probe, topic: str, n: int = 1) -> list:
    """Step the simulator n times, delivering each step's messages before the next."""
    for _ in range(n):
        before = len(probe.messages[topic])
        sim.step_once()
        probe.wait(topic, before + 1)
    return probe.messages[topic]


def stamp_s(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def test_laser_scan_fields(ros_context, executor, tmp_path) -> None:
    sim = make_sim(ros_context, executor, write_world(tmp_path, 'bot( pose [2 5 0 0] )'))
    probe = Probe(ros_context, executor)
    scans = probe.listen(LaserScan, "base_scan")
    assert spin_until(executor, lambda: sim.publishers_by_name["base_scan"].get_subscription_count() > 0)
    scan = step(executor, sim, probe, "base_scan")[-1]
    assert scan.header.frame_id == "base_laser_link"
    assert stamp_s(scan) == pytest.approx(0.1)
    assert scan.angle_min == pytest.approx(-math.pi / 2)
    assert scan.angle_max == pytest.approx(math.pi / 2)
    assert scan.angle_increment == pytest.approx(math.pi / 180)
    assert scan.angle_min + scan.angle_increment * (len(scan.ranges) - 1) == pytest.approx(scan.angle_max)
    assert len(scan.ranges) == len(scan.intensities) == 181
    assert (scan.range_min, scan.range_max) == pytest.approx((0.05, 8.0))
    assert scan.scan_time == pytest.approx(0.1) and scan.time_increment == 0.0
    core = sim.sim.scans[0][0]
    assert np.array_equal(np.asarray(scan.ranges, dtype=np.float32), core.ranges)
    # the north wall, 4.98 m to the left (Stage's walk does not reliably reach the east wall 7.88 m ahead with
    # an 8 m laser: it loses up to a step per empty region it jumps over, see sensing/stage_walk.py)
    assert scan.ranges[180] == pytest.approx(9.98 - 5.0, abs=1e-5)
    assert scan.intensities[180] == pytest.approx(1.0)
    assert len(scans) == 1


def test_odometry_and_ground_truth_after_a_known_command(ros_context, executor, tmp_path) -> None:
    sim = make_sim(ros_context, executor, write_world(tmp_path, 'bot( pose [2 5 0 90] )'))
    probe = Probe(ros_context, executor)
    odom = probe.listen(Odometry, "odom")
    truth = probe.listen(Odometry, "base_pose_ground_truth")
    driver = probe.node.create_publisher(Twist, "cmd_vel", 10)
    assert spin_until(executor, lambda: driver.get_subscription_count() > 0)
    cmd = Twist()
    cmd.linear.x, cmd.angular.z = 0.5, 0.2
    driver.publish(cmd)
    assert spin_until(executor, lambda: sim.sim.commands[0][0] == 0.5)
    step(executor, sim, probe, "odom")
    probe.wait("base_pose_ground_truth")
    o, t = odom[-1], truth[-1]
    assert (o.header.frame_id, o.child_frame_id) == ("odom", "base_footprint")
    assert (t.header.frame_id, t.child_frame_id) == ("world", "base_footprint")
    # heading 90° at the start of the step: 0.05 m along +y, yaw + 0.02 rad
    assert (t.pose.pose.position.x, t.pose.pose.position.y) == pytest.approx((2.0, 5.05))
    assert 2 * math.atan2(t.pose.pose.orientation.z, t.pose.pose.orientation.w) == pytest.approx(math.pi / 2 + 0.02)
    # odometry starts at 0 in the odom frame (start pose) and moves along its own x
    assert (o.pose.pose.position.x, o.pose.pose.position.y) == pytest.approx((0.05, 0.0))
    assert (o.twist.twist.linear.x, o.twist.twist.angular.z) == pytest.approx((0.5, 0.2))
    assert (t.twist.twist.linear.x, t.twist.twist.angular.z) == pytest.approx((0.5, 0.2))
    assert stamp_s(o) == stamp_s(t) == pytest.approx(0.1)


def test_tf_tree_shape_and_values(ros_context, executor, tmp_path) -> None:
    sim = make_sim(ros_context, executor, write_world(tmp_path, 'bot( pose [2 5 0 0] )'))
    probe = Probe(ros_context, executor)
    static = probe.listen(TFMessage, "/tf_static", LATCHED)
    tf = probe.listen(TFMessage, "/tf")
    probe.wait("/tf_static")
    edges = {(t.header.frame_id, t.child_frame_id): t.transform for t in static[0].transforms}
    assert set(edges) == {("base_footprint", "base_link"), ("base_link", "base_laser_link")}
    laser = edges[("base_link", "base_laser_link")]
    # x from the ranger pose, z = robot height 0.2 + ranger z −0.1
    assert (laser.translation.x, laser.translation.y, laser.translation.z) == pytest.approx((0.1, 0.0, 0.1))
    assert edges[("base_footprint", "base_link")].rotation.w == pytest.approx(1.0)
    assert spin_until(executor, lambda: sim.publishers_by_name["/tf"].get_subscription_count() > 0)
    sim.sim.set_velocity(0, 0.5, 0.0, 0.0)
    step(executor, sim, probe, "/tf")
    (odom_tf,) = tf[-1].transforms
    assert (odom_tf.header.frame_id, odom_tf.child_frame_id) == ("odom", "base_footprint")
    assert odom_tf.transform.translation.x == pytest.approx(0.05)
    assert stamp_s(odom_tf) == pytest.approx(0.1)
    for message in (*static, *tf):
        for t in message.transforms:
            assert not t.header.frame_id.startswith("/") and not t.child_frame_id.startswith("/")


def test_clock_is_monotonic_never_zero_and_steps_by_interval_sim(ros_context, executor, tmp_path) -> None:
    # Paced (100 clocks a wall second): /clock is reliable with a history of 10, as stage_ros has it, so a reader
    # starved for longer than 10 messages misses some. At speedup 0 that was under a millisecond, which a loaded
    # CI machine exceeded (gaps of 3.5 s of sim time).
    node = StageRos(str(write_world(tmp_path, 'bot( pose [2 5 0 0] )')), context=ros_context,
                    parameter_overrides=[Parameter("speedup", value=10.0)])
    executor.add_node(node)
    probe = Probe(ros_context, executor)
    clock = probe.listen(Clock, "/clock", 1000)
    probe.wait("/clock", 30)
    times = [c.clock.sec + c.clock.nanosec * 1e-9 for c in clock]
    assert times[0] > 0
    assert np.diff(times) == pytest.approx([0.1] * (len(times) - 1))


def test_watchdog_stops_the_robot_after_0_2_s_of_sim_time(ros_context, executor, tmp_path) -> None:
    sim = make_sim(ros_context, executor, write_world(tmp_path, 'bot( pose [2 5 0 0] )'))
    probe = Probe(ros_context, executor)
    odom = probe.listen(Odometry, "odom")
    driver = probe.node.create_publisher(Twist, "cmd_vel", 10)
    assert spin_until(executor, lambda: driver.get_subscription_count() > 0)
    cmd = Twist()
    cmd.linear.x = 0.5
    driver.publish(cmd)
    assert spin_until(executor, lambda: sim.sim.commands[0][0] == 0.5)
    step(executor, sim, probe, "odom", 4)
    speeds = [m.twist.twist.linear.x for m in odom]
    assert speeds == pytest.approx([0.5, 0.0, 0.0, 0.0])  # commanded at t=0: stopped at t=0.2 s


def test_reset_positions_service(ros_context, executor, tmp_path) -> None:
    sim = make_sim(ros_context, executor, write_world(tmp_path, 'bot( pose [2 5 0 0] )'), base_watchdog_timeout=0.0)
    probe = Probe(ros_context, executor)
    truth = probe.listen(Odometry, "base_pose_ground_truth")
    sim.sim.set_velocity(0, 0.5, 0.0, 0.5)
    step(executor, sim, probe, "base_pose_ground_truth", 5)
    assert truth[-1].pose.pose.position.x > 2.1
    client = probe.node.create_client(Empty, "reset_positions")
    assert spin_until(executor, client.service_is_ready)
    future = client.call_async(Empty.Request())
    executor.spin_until_future_complete(future, timeout_sec=5.0)
    assert future.done()
    step(executor, sim, probe, "base_pose_ground_truth")
    p = truth[-1].pose.pose
    assert (p.position.x, p.position.y, p.orientation.z) == pytest.approx((2.0, 5.0, 0.0))
    assert stamp_s(truth[-1]) == pytest.approx(0.6)  # time carries on


def test_stall_on_a_wall(ros_context, executor, tmp_path) -> None:
    sim = make_sim(ros_context, executor, write_world(tmp_path, 'bot( pose [9.5 5 0 0] )'), base_watchdog_timeout=0.0)
    probe = Probe(ros_context, executor)
    stall = probe.listen(Bool, "stall")
    truth = probe.listen(Odometry, "base_pose_ground_truth")
    sim.sim.set_velocity(0, 1.0, 0.0, 0.0)
    step(executor, sim, probe, "stall", 5)
    probe.wait("base_pose_ground_truth", 5)
    assert [m.data for m in stall] == [False, False, True, True, True]
    assert truth[-1].pose.pose.position.x == pytest.approx(9.7)
    assert truth[-1].twist.twist.linear.x == 0.0  # the true motion while stalled


def test_three_robot_names(ros_context, executor, tmp_path) -> None:
    world = write_world(tmp_path, 'bot( pose [2 2 0 0] ) bot( pose [5 5 0 0] name "alice" ) bot( pose [8 8 0 0] )')
    sim = make_sim(ros_context, executor, world)
    probe = Probe(ros_context, executor)
    static = probe.listen(TFMessage, "/tf_static", LATCHED)
    for i in range(3):
        probe.listen(LaserScan, f"robot_{i}/base_scan")
        probe.listen(Odometry, f"robot_{i}/odom")
    sim.step_once()
    for i in range(3):
        scan = probe.wait(f"robot_{i}/base_scan")[-1]
        odom = probe.wait(f"robot_{i}/odom")[-1]
        assert scan.header.frame_id == f"robot_{i}/base_laser_link"
        assert (odom.header.frame_id, odom.child_frame_id) == (f"robot_{i}/odom", f"robot_{i}/base_footprint")
    probe.wait("/tf_static")
    children = {t.child_frame_id for t in static[0].transforms}
    assert children == {f"robot_{i}/{f}" for i in range(3) for f in ("base_link", "base_laser_link")}
    topics = {name for name, _ in sim.get_topic_names_and_types()}
    assert {"/robot_1/cmd_vel", "/robot_1/base_pose_ground_truth", "/robot_1/stall"} <= topics


def test_model_names_with_use_model_names(ros_context, executor, tmp_path) -> None:
    world = write_world(tmp_path, 'bot( pose [2 2 0 0] name "alice" ) bot( pose [5 5 0 0] )')
    sim = make_sim(ros_context, executor, world, use_model_names=True)
    assert sim.names[0].topic("odom") == "alice/odom" and sim.names[0].laser_frames == ("alice/base_laser_link",)
    assert sim.names[1].topic("odom") == "robot_1/odom"  # Stage's automatic token is not a valid ROS name


def test_two_rangers_get_indexed_names(ros_context, executor, tmp_path) -> None:
    two = 'laser( pose [0.1 0 -0.1 0] ) laser( pose [-0.1 0 -0.1 180] )'
    sim = make_sim(ros_context, executor, write_world(tmp_path, 'bot( pose [5 5 0 0] )', body=two))
    probe = Probe(ros_context, executor)
    front = probe.listen(LaserScan, "base_scan_0")
    back = probe.listen(LaserScan, "base_scan_1")
    sim.step_once()
    probe.wait("base_scan_0")
    probe.wait("base_scan_1")
    assert front[0].header.frame_id == "base_laser_link_0"
    assert back[0].header.frame_id == "base_laser_link_1"
    # facing east from x = 5.1 / west from x = 4.9: walls' first cells [9.98, 10) and [0, 0.02); towards −x
    # Stage's walk reports the whole cells walked from x = 4.9 to the wall's cell 0 (its far side)
    assert front[0].ranges[90] == pytest.approx(4.88, abs=1e-5)
    assert back[0].ranges[90] == pytest.approx(4.9, abs=1e-5)


def test_publish_map(ros_context, executor, tmp_path) -> None:
    sim = make_sim(ros_context, executor, write_world(tmp_path, 'bot( pose [2 5 0 0] )'), publish_map=True)
    probe = Probe(ros_context, executor)
    maps = probe.listen(OccupancyGrid, "/map", LATCHED)
    grid = probe.wait("/map")[0]
    assert grid.header.frame_id == "world"
    assert grid.info.resolution == pytest.approx(0.02)
    assert (grid.info.width, grid.info.height) == (sim.sim.static.shape[1], sim.sim.static.shape[0])
    data = np.asarray(grid.data, dtype=np.int8).reshape(grid.info.height, grid.info.width)
    assert set(np.unique(data)) == {0, 100}
    # the cell under the robot is free, the east wall's column is occupied
    ox, oy = grid.info.origin.position.x, grid.info.origin.position.y
    assert data[int((5 - oy) / 0.02), int((2 - ox) / 0.02)] == 0
    assert data[int((5 - oy) / 0.02), int((9.99 - ox) / 0.02)] == 100
    assert len(maps) == 1


def test_bad_commands_are_rejected_and_the_previous_one_kept(ros_context, executor, tmp_path) -> None:
    sim = make_sim(ros_context, executor, write_world(tmp_path, 'bot( pose [2 5 0 0] )'))
    good, bad = Twist(), Twist()
    good.linear.x = 0.3
    sim.on_command(0, good)
    for value in (math.nan, math.inf, -math.inf, 5e3):
        bad.linear.x = value
        sim.on_command(0, bad)
        assert sim.sim.commands[0][0] == 0.3
    sim.step_once()
    assert sim.sim.true_poses[0][0] == pytest.approx(2.03)


def test_stamped_velocity_and_world_file_parameter(ros_context, executor, tmp_path) -> None:
    from geometry_msgs.msg import TwistStamped

    world = write_world(tmp_path, 'bot( pose [2 5 0 0] )')
    overrides = [Parameter("world_file", value=str(world)), Parameter("use_stamped_velocity", value=True)]
    sim = StageRos(None, autostep=False, context=ros_context, parameter_overrides=overrides)
    executor.add_node(sim)
    probe = Probe(ros_context, executor)
    driver = probe.node.create_publisher(TwistStamped, "cmd_vel", 10)
    assert spin_until(executor, lambda: driver.get_subscription_count() > 0)
    cmd = TwistStamped()
    cmd.twist.linear.x = 0.4
    driver.publish(cmd)
    assert spin_until(executor, lambda: sim.sim.commands[0][0] == pytest.approx(0.4))
    sim.step_once()
    assert sim.sim.true_poses[0][0] == pytest.approx(2.04)


def test_seed_parameter_fixes_the_drawn_odometry_error(ros_context, executor, tmp_path) -> None:
    world = tmp_path / "drawn.world"
    world.write_text(WORLD.replace('odom_error [0 0 0 0] ', '').format(body="") + 'bot( pose [2 5 0 0] )')
    a = StageRos(str(world), autostep=False, node_name="a", context=ros_context,
                 parameter_overrides=[Parameter("seed", value=4)])
    b = StageRos(str(world), autostep=False, node_name="b", context=ros_context,
                 parameter_overrides=[Parameter("seed", value=4)])
    c = StageRos(str(world), autostep=False, node_name="c", context=ros_context, seed=5)
    assert np.array_equal(a.sim.odom_errors, b.sim.odom_errors)
    assert not np.array_equal(a.sim.odom_errors, c.sim.odom_errors)
    for node in (a, b, c):
        node.destroy_node()


def test_real_time_on_two_threads_lets_idle_kernel_threads_sleep(ros_context, tmp_path, monkeypatch) -> None:
    """Paced to the wall clock, numba's workers sleep between steps instead of spinning; as fast as possible
    they keep spinning (the next step comes at once)."""
    import os

    world = write_world(tmp_path, 'bot( pose [2 5 0 0] )')
    monkeypatch.setenv("OMP_WAIT_POLICY", "")  # restored after the test
    monkeypatch.delenv("OMP_WAIT_POLICY")
    fast = StageRos(str(world), autostep=False, node_name="fast", context=ros_context, speedup=0.0, threads=2)
    assert "OMP_WAIT_POLICY" not in os.environ
    paced = StageRos(str(world), autostep=False, node_name="paced", context=ros_context, speedup=1.0, threads=2)
    assert os.environ["OMP_WAIT_POLICY"] == "PASSIVE"
    for node in (fast, paced):
        node.destroy_node()
