"""Topic and frame names per robot, following stageros' rules with tf2-valid frame ids.

One robot (and no ``-u``): plain relative names (``odom``, ``base_scan``). Several robots: ``robot_<i>/``
prefixes in world-file order, or the model's ``name`` with ``use_model_names`` when it is a valid ROS name
(Stage's automatic tokens such as ``position:0`` are not, and fall back to ``robot_<i>``). Several rangers
on one robot: ``base_scan_<k>`` and ``base_laser_link_<k>``. Frame ids never start with ``/`` (stage_ros'
multi-robot frames did, which tf2 rejects). Topics stay relative so they move with a node namespace.
Which topics there are is :mod:`stage_sim.interface.topics`' business; this module only prefixes and numbers.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_VALID_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def numbered(name: str, count: int) -> tuple[str, ...]:
    """One name per ranger: ``name`` alone for one ranger, ``name_<k>`` for several."""
    return (name,) if count == 1 else tuple(f"{name}_{k}" for k in range(count))


@dataclass(frozen=True)
class RobotNames:
    """Every name one robot uses on the ROS graph: its prefix (``''``, ``robot_<i>/`` or ``<model>/``) and frames."""

    prefix: str
    odom_frame: str
    base_footprint: str
    base_link: str
    laser_frames: tuple[str, ...]

    @property
    def label(self) -> str:
        """The prefix without its slash (``''`` for a lone robot): the robot's name on the ROS graph."""
        return self.prefix.rstrip("/")

    def topic(self, name: str) -> str:
        """A per-robot topic, e.g. ``odom`` → ``robot_0/odom``."""
        return self.prefix + name

    def ranger_topics(self, name: str) -> tuple[str, ...]:
        """A per-ranger topic on each of the robot's rangers, e.g. ``base_scan`` → ``robot_0/base_scan_1``."""
        return tuple(self.prefix + n for n in numbered(name, len(self.laser_frames)))


def robot_prefix(index: int, model_name: str, robot_count: int, use_model_names: bool) -> str:
    """'' for a lone robot, else 'robot_<i>/' or '<model name>/'."""
    if robot_count == 1 and not use_model_names:
        return ""
    if use_model_names and _VALID_NAME.match(model_name):
        return f"{model_name}/"
    return f"robot_{index}/"


def robot_names(
    index: int, model_name: str, robot_count: int, ranger_count: int, use_model_names: bool = False
) -> RobotNames:
    """The names of robot ``index`` given how many robots and rangers the world has."""
    p = robot_prefix(index, model_name, robot_count, use_model_names)
    return RobotNames(
        prefix=p,
        odom_frame=f"{p}odom",
        base_footprint=f"{p}base_footprint",
        base_link=f"{p}base_link",
        laser_frames=tuple(p + f for f in numbered("base_laser_link", ranger_count)),
    )
