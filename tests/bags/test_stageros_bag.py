"""``stageros --bag``: the bag holds, byte for byte, what the node publishes, with ROS's own type hashes."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import pytest
from mcap.reader import make_reader
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from stage_sim.ros.bag_recording import bag_recording
from stage_sim.ros.stageros import StageRos
from tests.bags.readers import READERS
from tests.bags.worlds import ROBOT_TOPICS, two_robot_world
from tests.ros.conftest import executor, ros_context  # noqa: F401 - the ROS tests' fixtures
from tests.ros.helpers import spin_until

STEPS = 5
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def raw_bag_messages(path: Path) -> dict[str, list[bytes]]:
    messages = defaultdict(list)
    with path.open("rb") as stream:
        for _, channel, message in make_reader(stream).iter_messages(log_time_order=False):
            messages[channel.topic].append(bytes(message.data))
    return messages


def test_the_bag_holds_exactly_what_stageros_publishes(ros_context, executor, tmp_path) -> None:  # noqa: F811
    stage = StageRos(two_robot_world(tmp_path), speedup=0.0, seed=2, autostep=False, context=ros_context)
    executor.add_node(stage)
    listener = Node("bag_listener", context=ros_context)
    executor.add_node(listener)
    received: dict[str, list[bytes]] = defaultdict(list)
    topics = {"/clock": "rosgraph_msgs/msg/Clock", "/tf": "tf2_msgs/msg/TFMessage"} | {
        f"/robot_{i}/{name}": "" for i in range(2) for name in ROBOT_TOPICS}
    publishers = {name: types for name, types in stage.get_publisher_names_and_types_by_node("stageros", "/")}
    for topic in topics:
        msg_type = _message_class(publishers[topic][0])
        listener.create_subscription(msg_type, topic, lambda data, t=topic: received[t].append(data), 10, raw=True)
    listener.create_subscription(_message_class("tf2_msgs/msg/TFMessage"), "/tf_static",
                                 lambda data: received["/tf_static"].append(data), LATCHED, raw=True)
    assert spin_until(executor, lambda: all(stage.count_subscribers(t) for t in topics), 10.0)
    bag_path = tmp_path / "stageros.mcap"
    with bag_recording(stage, argparse.Namespace(bag=bag_path, bag_topics=None), "stageros"):
        stage.sim.set_velocity(0, 0.4, 0.0, 0.3)
        stage.sim.set_velocity(1, 0.2, 0.0, -0.2)
        for _ in range(STEPS):
            stage.step_once()
        assert spin_until(executor, lambda: all(len(received[t]) == STEPS for t in topics) and received["/tf_static"])
    recorded = raw_bag_messages(bag_path)
    assert set(recorded) == {*topics, "/tf_static"}
    for topic, published in received.items():
        assert recorded[topic] == published, topic


def test_the_bag_names_the_types_with_ros_own_hashes(tmp_path) -> None:
    from stage_sim.bags.recorder import BagRecorder
    from stage_sim.interface.names import robot_names
    from stage_sim.sim.simulation import Simulation
    from stage_sim.worldfile.loader import load_world

    sim = Simulation(load_world(two_robot_world(tmp_path)))
    names = [robot_names(r.index, r.name, 2, len(r.rangers)) for r in sim.robots]
    BagRecorder(sim, tmp_path / "h.mcap", names, with_map=True).close()
    with (tmp_path / "h.mcap").open("rb") as stream:
        summary = make_reader(stream).get_summary()
    for channel in summary.channels.values():
        msgtype = summary.schemas[channel.schema_id].name
        package, _, name = msgtype.split("/")
        description = json.loads(Path(sys.prefix, "share", package, "msg", f"{name}.json").read_text())  # the wheels'
        ros_hash = next(h["hash_string"] for h in description["type_hashes"] if h["type_name"] == msgtype)
        assert channel.metadata["topic_type_hash"] == ros_hash, msgtype


@pytest.mark.slow
def test_stageros_finalises_the_bag_at_quit_time(tmp_path) -> None:
    bag_path = tmp_path / "quit.mcap"
    result = subprocess.run(
        [str(Path(sys.executable).with_name("stageros")), "-g", str(two_robot_world(tmp_path, quit_time=1.0)),
         "--speedup", "0", "--bag", str(bag_path), "--bag-topics", "/clock", "robot_1/base_scan_1"],
        capture_output=True, text=True, timeout=120, env=dict(os.environ))
    assert result.returncode == 0, result.stderr
    assert f"stageros: bag {bag_path}: 20 messages" in result.stderr
    assert READERS["rosbags"](bag_path).counts() == {"/clock": 10, "/robot_1/base_scan_1": 10}


@pytest.mark.slow
def test_stageros_refuses_a_bag_it_cannot_write(tmp_path) -> None:
    result = subprocess.run(
        [str(Path(sys.executable).with_name("stageros")), "-g", str(two_robot_world(tmp_path)), "--bag",
         str(tmp_path / "missing" / "x.mcap")], capture_output=True, text=True, timeout=120, env=dict(os.environ))
    assert result.returncode == 2
    assert "stageros: cannot write bag" in result.stderr and "Traceback" not in result.stderr


def _message_class(type_name: str) -> type:
    package, _, name = type_name.split("/")
    return getattr(__import__(f"{package}.msg", fromlist=[name]), name)
