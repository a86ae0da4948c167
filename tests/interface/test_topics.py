"""The interface registry: every topic stageros offers, its names per world, its QoS and its values (no ROS)."""

from __future__ import annotations

import numpy as np
import pytest

from stage_sim.interface import qos, topics
from stage_sim.interface.names import robot_names
from stage_sim.interface.topics import Scope, Timing
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world, load_world_text
from tests.bags.worlds import two_robot_world


def _names(sim: Simulation, use_model_names: bool = False):
    return [robot_names(r.index, r.name, len(sim.robots), len(r.rangers), use_model_names) for r in sim.robots]


@pytest.fixture(scope="module")
def two_robots(tmp_path_factory) -> Simulation:
    return Simulation(load_world(two_robot_world(tmp_path_factory.mktemp("world"))), seed=3)


def test_the_published_topics_their_types_and_qos() -> None:
    offered = {t.name: (t.msgtype, t.qos, t.scope, t.timing) for t in topics.published(with_map=True)}
    reliable_10 = qos.Qos(depth=10, reliability=qos.Reliability.RELIABLE, durability=qos.Durability.VOLATILE,
                          history=qos.History.KEEP_LAST)
    latched = qos.Qos(depth=1, durability=qos.Durability.TRANSIENT_LOCAL)
    assert offered == {
        "/clock": ("rosgraph_msgs/msg/Clock", reliable_10, Scope.WORLD, Timing.STEP),
        "odom": ("nav_msgs/msg/Odometry", reliable_10, Scope.ROBOT, Timing.STEP),
        "base_pose_ground_truth": ("nav_msgs/msg/Odometry", reliable_10, Scope.ROBOT, Timing.STEP),
        "stall": ("std_msgs/msg/Bool", reliable_10, Scope.ROBOT, Timing.STEP),
        "base_scan": ("sensor_msgs/msg/LaserScan", reliable_10, Scope.RANGER, Timing.MEASURED),
        "/tf": ("tf2_msgs/msg/TFMessage", qos.Qos(depth=100), Scope.WORLD, Timing.STEP),
        "/tf_static": ("tf2_msgs/msg/TFMessage", latched, Scope.WORLD, Timing.START),
        "/map": ("nav_msgs/msg/OccupancyGrid", latched, Scope.WORLD, Timing.START),
    }
    assert "/map" not in {t.name for t in topics.published(with_map=False)}


def test_the_subscribed_command_topic_plain_or_stamped() -> None:
    assert [(t.name, t.msgtype, t.qos.depth) for t in topics.subscribed(stamped=False)] == [
        ("cmd_vel", "geometry_msgs/msg/Twist", 10)]
    assert [t.msgtype for t in topics.subscribed(stamped=True)] == ["geometry_msgs/msg/TwistStamped"]
    assert qos.EVERY_REQUEST.history is qos.History.KEEP_ALL


def test_endpoints_follow_the_name_rules(two_robots) -> None:
    names = _names(two_robots)
    assert [e.name for e in topics.endpoints(topics.CLOCK, names)] == ["/clock"]
    assert [(e.name, e.robot) for e in topics.endpoints(topics.STALL, names)] == [
        ("robot_0/stall", 0), ("robot_1/stall", 1)]
    assert [(e.name, e.robot, e.ranger) for e in topics.endpoints(topics.SCAN, names)] == [
        ("robot_0/base_scan_0", 0, 0), ("robot_0/base_scan_1", 0, 1),
        ("robot_1/base_scan_0", 1, 0), ("robot_1/base_scan_1", 1, 1)]
    by_model = _names(two_robots, use_model_names=True)
    assert [e.name for e in topics.endpoints(topics.CMD_VEL, by_model)] == ["alpha/cmd_vel", "beta/cmd_vel"]
    assert [n.label for n in by_model] == ["alpha", "beta"]


def test_a_lone_robot_with_one_laser_has_plain_relative_names() -> None:
    sim = Simulation(load_world_text("define l ranger( sensor( range [0 5] fov 180 samples 5 ) )\n"
                                     "position( pose [0 0 0 0] l() )\n"))
    (names,) = _names(sim)
    assert (names.label, names.topic("odom"), names.ranger_topics("base_scan")) == ("", "odom", ("base_scan",))
    assert names.laser_frames == ("base_laser_link",)


def test_values_are_the_simulation_state_of_the_step(two_robots) -> None:
    sim, names = two_robots, _names(two_robots)
    sim.set_velocity(0, 0.3, 0.0, 0.2)
    sim.step()
    poses, velocities = topics.ODOM.values(sim, names)
    assert poses is sim.odometry_poses and velocities is sim.velocities
    truth, true_velocities = topics.GROUND_TRUTH.values(sim, names)
    assert truth is sim.true_poses
    np.testing.assert_array_equal(true_velocities, sim.true_velocities)
    assert topics.CLOCK.values(sim, names) == sim.sim_time_us
    scans = topics.SCAN.values(sim, names)
    assert scans.measured(0, 1) is sim.scans[0][1]
    edges = topics.TF_STATIC.values(sim, names)
    assert [(e.parent, e.child) for e in edges[:3]] == [
        ("robot_0/base_footprint", "robot_0/base_link"), ("robot_0/base_link", "robot_0/base_laser_link_0"),
        ("robot_0/base_link", "robot_0/base_laser_link_1")]


def test_a_slow_ranger_publishes_only_in_the_steps_it_measured() -> None:
    sim = Simulation(load_world_text(
        "interval_sim 100\ndefine l ranger( sensor( range [0 5] fov 180 samples 5 ) update_interval 200 )\n"
        "position( pose [0 0 0 0] l() )\n"))
    measured = []
    for _ in range(4):
        sim.step()
        latest = topics.SCAN.values(sim, _names(sim))
        kept = latest.snapshot()
        measured.append(latest.measured(0, 0) is not None)
        assert kept.measured(0, 0) is latest.measured(0, 0)
    assert measured.count(True) == 2
