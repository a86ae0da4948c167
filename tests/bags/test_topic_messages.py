"""The bag side of the interface registry: a message for every topic, and the QoS rosbag2 records for it."""

from __future__ import annotations

from rosbags.interfaces import QosDurability, QosHistory, QosReliability

from stage_sim.bags.messages import TOPIC_MESSAGES, TYPESTORE
from stage_sim.bags.topics import bag_qos
from stage_sim.interface import qos, topics


def test_every_published_topic_has_a_message_the_typestore_knows() -> None:
    assert set(TOPIC_MESSAGES) == set(topics.PUBLISHED)
    assert all(topic.msgtype in TYPESTORE.types for topic in topics.PUBLISHED)


def test_plain_profiles_become_the_recorded_ones() -> None:
    latched = bag_qos(qos.LATCHED)
    assert (latched.history, latched.depth, latched.reliability, latched.durability) == (
        QosHistory.KEEP_LAST, 1, QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL)
    tf = bag_qos(qos.TF_STREAM)
    assert (tf.depth, tf.reliability, tf.durability) == (100, QosReliability.RELIABLE, QosDurability.VOLATILE)
