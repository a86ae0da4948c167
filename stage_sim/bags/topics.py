"""What a bag of a simulation holds: every topic stageros publishes, with its type and offered QoS.

The list is the interface registry's (:mod:`stage_sim.interface.topics`). Names are fully qualified as
``ros2 bag record`` stores them (the node namespace before the relative per-robot names); the QoS profiles
are stageros' own, written the way rosbag2 writes a topic's ``offered_qos_profiles`` so that ``ros2 bag play``
offers them again (late joiners still get /tf_static).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from io import StringIO

from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag2.metadata import dump_qos_v9
from ruamel.yaml import YAML

from stage_sim.interface import qos as plain
from stage_sim.interface import topics
from stage_sim.interface.names import RobotNames
from stage_sim.interface.topics import Endpoint, Scope

# RMW_DURATION_INFINITE, as rosbag2 records an unset deadline, lifespan and lease duration.
_INFINITE = QosTime(sec=9223372036, nsec=854775807)
_RELIABILITY = {plain.Reliability.RELIABLE: QosReliability.RELIABLE,
                plain.Reliability.BEST_EFFORT: QosReliability.BEST_EFFORT}
_DURABILITY = {plain.Durability.VOLATILE: QosDurability.VOLATILE,
               plain.Durability.TRANSIENT_LOCAL: QosDurability.TRANSIENT_LOCAL}
_HISTORY = {plain.History.KEEP_LAST: QosHistory.KEEP_LAST, plain.History.KEEP_ALL: QosHistory.KEEP_ALL}


def bag_qos(qos: plain.Qos) -> Qos:
    """The profile rosbag2 records for a publisher offering ``qos``."""
    return Qos(_HISTORY[qos.history], qos.depth, _RELIABILITY[qos.reliability], _DURABILITY[qos.durability],
               _INFINITE, _INFINITE, QosLiveliness.AUTOMATIC, _INFINITE, False)


def yaml_text(data: object) -> str:
    """Block-style YAML, as rosbag2's metadata strings are written."""
    stream = StringIO()
    yaml = YAML(typ="safe")
    yaml.default_flow_style = False
    yaml.dump(data, stream)
    return stream.getvalue()


@dataclass(frozen=True)
class Topic:
    """One recorded topic: its fully qualified name and the interface endpoint it records."""

    name: str
    endpoint: Endpoint

    @property
    def msgtype(self) -> str:
        return self.endpoint.topic.msgtype

    @property
    def qos(self) -> Qos:
        return bag_qos(self.endpoint.topic.qos)

    def offered_qos_profiles(self) -> str:
        """The channel metadata value rosbag2 writes (metadata version 9: a YAML list of profiles)."""
        return _offered_qos_profiles(self.endpoint.topic.qos)


@cache
def _offered_qos_profiles(qos: plain.Qos) -> str:
    """:meth:`Topic.offered_qos_profiles` of a publisher offering ``qos``, made once per profile (a YAML dump takes
    milliseconds, and a bag of 100 robots has 400 channels of a few profiles)."""
    return yaml_text(dump_qos_v9([bag_qos(qos)]))


def qualify(namespace: str, name: str) -> str:
    """A relative topic name resolved in a node namespace (absolute names stay as they are)."""
    if name.startswith("/"):
        return name
    return f"{namespace.rstrip('/')}/{name}"


def stageros_topics(names: Sequence[RobotNames], with_map: bool, namespace: str = "/") -> list[Topic]:
    """Every topic stageros publishes, qualified in ``namespace``: world topics first, then robot by robot."""
    published = topics.published(with_map)
    world = [e for t in published if t.scope is Scope.WORLD for e in topics.endpoints(t, names)]
    per_robot = sorted((e for t in published if t.scope is not Scope.WORLD for e in topics.endpoints(t, names)),
                       key=lambda e: e.robot)
    return [Topic(qualify(namespace, e.name), e) for e in world + per_robot]


def select(recorded: list[Topic], wanted: list[str] | None, namespace: str = "/") -> list[Topic]:
    """The topics named in ``wanted`` (relative names are resolved in ``namespace``; None: all of them).

    Raises ValueError naming the unknown ones and what could be recorded instead."""
    if not wanted:
        return recorded
    known = [t.name for t in recorded]
    resolved = {qualify(namespace, name): name for name in wanted}
    unknown = [name for full, name in resolved.items() if full not in known]
    if unknown:
        raise ValueError(f"no such topic {', '.join(unknown)}; this world publishes {', '.join(known)}")
    return [t for t in recorded if t.name in resolved]
