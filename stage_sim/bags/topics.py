"""What a bag of a simulation holds: every topic stageros publishes, with its type and offered QoS.

Names are fully qualified as ``ros2 bag record`` stores them (the node namespace before the relative
per-robot names); the QoS profiles are stageros' own (design: /clock and per-robot topics reliable depth 10,
/tf depth 100, /tf_static and /map transient-local depth 1), written the way rosbag2 writes a topic's
``offered_qos_profiles`` so that ``ros2 bag play`` offers them again (late joiners still get /tf_static).
"""

from __future__ import annotations

from dataclasses import dataclass
from io import StringIO

from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag2.metadata import dump_qos_v9
from ruamel.yaml import YAML

from stage_sim.bags.names import RobotNames

# RMW_DURATION_INFINITE, as rosbag2 records an unset deadline, lifespan and lease duration.
_INFINITE = QosTime(sec=9223372036, nsec=854775807)


def _reliable(depth: int, durability: QosDurability = QosDurability.VOLATILE) -> Qos:
    return Qos(QosHistory.KEEP_LAST, depth, QosReliability.RELIABLE, durability, _INFINITE, _INFINITE,
               QosLiveliness.AUTOMATIC, _INFINITE, False)


RELIABLE_10 = _reliable(10)
TF_QOS = _reliable(100)
LATCHED = _reliable(1, QosDurability.TRANSIENT_LOCAL)

CLOCK, TF, TF_STATIC, MAP = "/clock", "/tf", "/tf_static", "/map"


def yaml_text(data: object) -> str:
    """Block-style YAML, as rosbag2's metadata strings are written."""
    stream = StringIO()
    yaml = YAML(typ="safe")
    yaml.default_flow_style = False
    yaml.dump(data, stream)
    return stream.getvalue()


@dataclass(frozen=True)
class Topic:
    """One recorded topic."""

    name: str
    msgtype: str
    qos: Qos

    def offered_qos_profiles(self) -> str:
        """The channel metadata value rosbag2 writes (metadata version 9: a YAML list of profiles)."""
        return yaml_text(dump_qos_v9([self.qos]))


@dataclass(frozen=True)
class RobotTopics:
    """The fully qualified topic names of one robot."""

    odom: str
    ground_truth: str
    stall: str
    scans: tuple[str, ...]


def qualify(namespace: str, name: str) -> str:
    """A relative topic name resolved in a node namespace (absolute names stay as they are)."""
    if name.startswith("/"):
        return name
    return f"{namespace.rstrip('/')}/{name}"


def robot_topics(names: list[RobotNames], namespace: str = "/") -> list[RobotTopics]:
    """Each robot's published topics, qualified in ``namespace``."""
    return [
        RobotTopics(qualify(namespace, n.odom), qualify(namespace, n.ground_truth), qualify(namespace, n.stall),
                    tuple(qualify(namespace, s) for s in n.scans))
        for n in names
    ]


def stageros_topics(robots: list[RobotTopics], with_map: bool) -> list[Topic]:
    """Every topic stageros publishes, world topics first, then robot by robot."""
    topics = [
        Topic(CLOCK, "rosgraph_msgs/msg/Clock", RELIABLE_10),
        Topic(TF, "tf2_msgs/msg/TFMessage", TF_QOS),
        Topic(TF_STATIC, "tf2_msgs/msg/TFMessage", LATCHED),
    ]
    if with_map:
        topics.append(Topic(MAP, "nav_msgs/msg/OccupancyGrid", LATCHED))
    for robot in robots:
        topics.append(Topic(robot.odom, "nav_msgs/msg/Odometry", RELIABLE_10))
        topics.append(Topic(robot.ground_truth, "nav_msgs/msg/Odometry", RELIABLE_10))
        topics.append(Topic(robot.stall, "std_msgs/msg/Bool", RELIABLE_10))
        topics.extend(Topic(scan, "sensor_msgs/msg/LaserScan", RELIABLE_10) for scan in robot.scans)
    return topics


def select(topics: list[Topic], wanted: list[str] | None, namespace: str = "/") -> list[Topic]:
    """The topics named in ``wanted`` (relative names are resolved in ``namespace``; None: all of them).

    Raises ValueError naming the unknown ones and what could be recorded instead."""
    if not wanted:
        return topics
    known = [t.name for t in topics]
    resolved = {qualify(namespace, name): name for name in wanted}
    unknown = [name for full, name in resolved.items() if full not in known]
    if unknown:
        raise ValueError(f"no such topic {', '.join(unknown)}; this world publishes {', '.join(known)}")
    return [t for t in topics if t.name in resolved]
