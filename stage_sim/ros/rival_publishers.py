"""Two simulators on one ROS domain is always a mistake: say so, naming the other node.

Each would obey the other's controllers and publish over the other's ``/clock`` and scans; the runs
corrupt each other silently. A simulator owns ``/clock`` and its robots' odometry and scans, so any
second publisher of one of them, from another node (or another node of the same name), is reported once
as an error. The check runs at start and every few wall seconds (discovery takes a moment), looking at
``/clock`` and a rotating batch of robot topics so that a thousand robots cost no more than one.
"""

from __future__ import annotations

from rclpy.clock import Clock, ClockType
from rclpy.node import Node

CHECK_PERIOD_S = 3.0
ROBOT_TOPICS_PER_CHECK = 32
"""About 100 µs per topic query: /clock plus this many robot topics keep a check under 5 ms."""


class RivalPublishers:
    """Watches ``always`` every check and ``rotating`` a batch at a time for publishers from other nodes."""

    def __init__(self, node: Node, always: list[str], rotating: list[str]) -> None:
        self.node = node
        self.always = [node.resolve_topic_name(t) for t in always]
        self.rotating = [node.resolve_topic_name(t) for t in rotating]
        self.reported: set[tuple[str, str]] = set()
        self._next = 0
        self.check()
        node.create_timer(CHECK_PERIOD_S, self.check, clock=Clock(clock_type=ClockType.STEADY_TIME))

    def check(self) -> None:
        """Log an error for every (topic, other node) pair not reported yet."""
        batch = self.rotating[self._next:self._next + ROBOT_TOPICS_PER_CHECK]
        self._next = 0 if self._next + ROBOT_TOPICS_PER_CHECK >= len(self.rotating) else self._next + len(batch)
        own = self.node.get_fully_qualified_name()
        for topic in [*self.always, *batch]:
            found = self.node.get_publishers_info_by_topic(topic)
            publishers = [_qualified(i.node_namespace, i.node_name) for i in found]
            if own in publishers:
                publishers.remove(own)  # this node's own publisher; a second one of that name is another process
            for other in publishers:
                if (topic, other) not in self.reported:
                    self.reported.add((topic, other))
                    who = f"another node named {other} as well" if other == own else f"another node, {other},"
                    self.node.get_logger().error(
                        f"{who} publishes {topic} on ROS_DOMAIN_ID "
                        f"{self.node.context.get_domain_id()}: two simulators (or a simulator and a recording or "
                        "driver) on one domain corrupt each other's runs; give each its own ROS_DOMAIN_ID")


def _qualified(namespace: str, name: str) -> str:
    return f"{namespace.rstrip('/')}/{name}"
