"""The ROS side of the interface registry: a message for every topic, of the registry's type, with its QoS."""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from stage_sim.interface import qos, topics
from stage_sim.ros.qos import qos_profile
from stage_sim.ros.topic_messages import TOPIC_MESSAGES, message_class


def test_every_published_topic_has_a_message_of_its_registered_type() -> None:
    assert set(TOPIC_MESSAGES) == set(topics.PUBLISHED)
    for topic in (*topics.PUBLISHED, topics.CMD_VEL, topics.CMD_VEL_STAMPED):
        cls = message_class(topic)
        assert f"{cls.__module__.split('.')[0]}/msg/{cls.__name__}" == topic.msgtype


def test_the_profiles_are_those_stageros_has_always_offered() -> None:
    assert qos_profile(qos.RELIABLE_10) == QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    assert qos_profile(qos.TF_STREAM) == QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
    assert qos_profile(qos.LATCHED) == QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    assert qos_profile(qos.NEWEST_ONLY) == QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
    assert qos_profile(qos.EVERY_REQUEST) == QoSProfile(
        history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)
