"""A bag read back the way users read one: with rosbags, and with mcap + mcap-ros2-support."""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader


@dataclass
class ReadBag:
    """What a reader saw: per topic its type, offered QoS text or objects, and (log time, message) in order."""

    types: dict[str, str] = field(default_factory=dict)
    qos: dict[str, Any] = field(default_factory=dict)
    messages: dict[str, list[tuple[int, Any]]] = field(default_factory=lambda: defaultdict(list))

    def counts(self) -> dict[str, int]:
        return {topic: len(items) for topic, items in self.messages.items()}


def read_with_rosbags(path: Path) -> ReadBag:
    bag = ReadBag()
    with AnyReader([path]) as reader:
        for connection in reader.connections:
            bag.types[connection.topic] = connection.msgtype
            bag.qos[connection.topic] = connection.ext.offered_qos_profiles
        for connection, log_time, raw in reader.messages():
            bag.messages[connection.topic].append((log_time, reader.deserialize(raw, connection.msgtype)))
    return bag


def read_with_mcap(path: Path) -> ReadBag:
    bag = ReadBag()
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        for channel in summary.channels.values():
            bag.types[channel.topic] = summary.schemas[channel.schema_id].name
            bag.qos[channel.topic] = channel.metadata["offered_qos_profiles"]
        for _, channel, message, decoded in reader.iter_decoded_messages(log_time_order=False):
            bag.messages[channel.topic].append((message.log_time, decoded))
    return bag


READERS = {"rosbags": read_with_rosbags, "mcap": read_with_mcap}
