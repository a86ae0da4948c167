"""The one registry of the topics stageros publishes and subscribes, without ROS.

Each :class:`Topic` says its name rule (absolute for the world, relative under a robot's prefix, numbered per
ranger), its message type, its QoS, when it is published and which values of a :class:`Simulation` its
messages carry (a per-step topic's are derived from some of the step's :class:`Quantity`, which a recording
copies once a step however many topics read them). The ROS node (:mod:`stage_sim.ros.stageros`) advertises and
publishes them in a loop over this registry, the bag recorder (:mod:`stage_sim.bags`) records the same list;
each side keeps one message filler per topic (:mod:`stage_sim.ros.topic_messages`, :mod:`stage_sim.bags.messages`).
The bag side fills its rosbags messages only for the latched topics and for the one template per endpoint of the
per-step ones, whose serialised bytes it then refills in place (:mod:`stage_sim.bags.layouts`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import Enum
from operator import attrgetter
from typing import TYPE_CHECKING, Any

import numpy as np

from stage_sim.interface import fields, frames
from stage_sim.interface.names import RobotNames
from stage_sim.interface.qos import LATCHED, RELIABLE_10, TF_STREAM, Qos
from stage_sim.sim.kinematics import true_velocities

if TYPE_CHECKING:
    from stage_sim.sim.simulation import Simulation


class Scope(Enum):
    """How many of a topic there are."""

    WORLD = "world"  # one, absolute name
    ROBOT = "robot"  # one per robot, under its prefix
    RANGER = "ranger"  # one per ranger of a robot, numbered when it has several


class Timing(Enum):
    """When a published topic sends."""

    STEP = "every step"
    MEASURED = "in the steps its ranger measured in"
    """Its values answer ``measured(robot, ranger)`` with this step's measurement or None."""
    START = "once at start, latched"


Values = Callable[["Simulation", Sequence[RobotNames]], Any]
"""What one publication of a topic is made of (world topics: the value; robot topics: indexed by robot)."""


@dataclass(frozen=True, eq=False)
class Quantity:
    """One thing a step's topics are made of, read off the simulation. Several topics read the same one (odom and
    /tf the odometry poses, /clock the sim time that stamps every message): a recording copies each once a step."""

    name: str
    read: Callable[[Simulation], Any]
    kept: str
    """The attribute of the simulation a recording keeps of each step, by reference (the simulation never writes
    an array it has exposed, it replaces it): ``read``'s value, or what that is made of besides the sim time."""


def _attribute(name: str) -> Quantity:
    """The quantity that is the simulation's attribute ``name``, read and kept as it is."""
    return Quantity(name, attrgetter(name), name)


SIM_TIME_US = _attribute("sim_time_us")
ODOMETRY_POSES = _attribute("odometry_poses")
VELOCITIES = _attribute("velocities")
TRUE_POSES = _attribute("true_poses")
STALLED = _attribute("stalled")
SCANS = Quantity("scans", fields.latest_scans, "measured_beams")


def _same(value: Any) -> Any:
    """The values of a topic that reads one quantity: that quantity as it is."""
    return value


@dataclass(frozen=True)
class StepValues:
    """A per-step topic's values (a :data:`Values`) made of some of the step's quantities by ``derive``. ``derive``
    takes one step's quantities as well as many steps' stacked (a leading axis per step): a recording copies
    the quantities, not the values, and derives the values of a whole batch of steps in its writer process."""

    reads: tuple[Quantity, ...]
    derive: Callable[..., Any] = _same

    def __call__(self, sim: Simulation, names: Sequence[RobotNames]) -> Any:
        return self.derive(*[quantity.read(sim) for quantity in self.reads])


def _ground_truth(poses: np.ndarray, velocities: np.ndarray, stalled: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The true poses and twists of one step or a stack of steps: a recording copies the velocities and stall
    flags, which other topics read too, and derives these in its writer process."""
    return poses, true_velocities(velocities, stalled)


@dataclass(frozen=True)
class Topic:
    """One topic of stageros' interface."""

    name: str
    """``/clock`` (world: absolute), ``odom`` (per robot: under its prefix), ``base_scan`` (per ranger:
    ``base_scan_<k>`` on a robot with several)."""
    msgtype: str
    qos: Qos
    scope: Scope
    timing: Timing = Timing.STEP
    values: Values | None = None
    """None for the topics stageros subscribes."""
    on_request: bool = False
    """Published only when asked for (/map: the ``publish_map`` parameter, ``--map``)."""

    def __reduce__(self) -> tuple[Callable[[str, str], Topic], tuple[str, str]]:
        """Pickled as a reference to the registry's entry (its values are functions): the bag writer process
        receives endpoints this way."""
        return registered, (self.name, self.msgtype)

    def names_on(self, robot: RobotNames) -> tuple[str, ...]:
        """The topic's names on one robot (one per ranger for a per-ranger topic)."""
        if self.scope is Scope.RANGER:
            return robot.ranger_topics(self.name)
        return (robot.topic(self.name),)


@dataclass(frozen=True)
class Endpoint:
    """One advertised instance of a topic: its full relative or absolute name and whose it is."""

    topic: Topic
    name: str
    robot: int | None = None
    ranger: int | None = None


Build = Callable[[Endpoint, "Simulation", Sequence[RobotNames]], Any]
"""(endpoint, simulation, robot names) → the endpoint's message with everything that never changes."""
Fill = Callable[[Any, Any, Endpoint, Any], Any]
"""(built message, the topic's values this step, endpoint, stamp) → the message to send, None for none."""


@dataclass(frozen=True)
class TopicMessage:
    """How one writer of messages (rclpy in :mod:`stage_sim.ros`, rosbags in :mod:`stage_sim.bags`) makes a
    topic's message: built once per endpoint, refilled for every publication (the bags refill the bytes of
    the per-step messages instead, from a template this makes)."""

    build: Build
    fill: Fill


def endpoints(topic: Topic, names: Sequence[RobotNames]) -> list[Endpoint]:
    """Every instance of ``topic`` in a world whose robots are called ``names``, robot by robot."""
    if topic.scope is Scope.WORLD:
        return [Endpoint(topic, topic.name)]
    return [Endpoint(topic, name, robot, k if topic.scope is Scope.RANGER else None)
            for robot, robot_names in enumerate(names) for k, name in enumerate(topic.names_on(robot_names))]


CLOCK = Topic("/clock", "rosgraph_msgs/msg/Clock", RELIABLE_10, Scope.WORLD, values=StepValues((SIM_TIME_US,)))
ODOM = Topic("odom", "nav_msgs/msg/Odometry", RELIABLE_10, Scope.ROBOT,
             values=StepValues((ODOMETRY_POSES, VELOCITIES), lambda poses, velocities: (poses, velocities)))
GROUND_TRUTH = Topic("base_pose_ground_truth", "nav_msgs/msg/Odometry", RELIABLE_10, Scope.ROBOT,
                     values=StepValues((TRUE_POSES, VELOCITIES, STALLED), _ground_truth))
STALL = Topic("stall", "std_msgs/msg/Bool", RELIABLE_10, Scope.ROBOT, values=StepValues((STALLED,)))
SCAN = Topic("base_scan", "sensor_msgs/msg/LaserScan", RELIABLE_10, Scope.RANGER, Timing.MEASURED,
             values=StepValues((SCANS,)))
TF = Topic("/tf", "tf2_msgs/msg/TFMessage", TF_STREAM, Scope.WORLD, values=StepValues((ODOMETRY_POSES,)))
"""One message per step with every robot's ``odom → base_footprint``."""
TF_STATIC = Topic("/tf_static", "tf2_msgs/msg/TFMessage", LATCHED, Scope.WORLD, Timing.START,
                  values=lambda sim, names: frames.static_edges(sim.robots, list(names)))
MAP = Topic("/map", "nav_msgs/msg/OccupancyGrid", LATCHED, Scope.WORLD, Timing.START,
            values=lambda sim, names: sim.static.to_occupancy_grid(), on_request=True)

PUBLISHED = (CLOCK, ODOM, GROUND_TRUTH, STALL, SCAN, TF, TF_STATIC, MAP)
"""Every topic stageros publishes; the per-step ones in the order it publishes them each step."""

CMD_VEL = Topic("cmd_vel", "geometry_msgs/msg/Twist", RELIABLE_10, Scope.ROBOT)
CMD_VEL_STAMPED = Topic("cmd_vel", "geometry_msgs/msg/TwistStamped", RELIABLE_10, Scope.ROBOT)
"""cmd_vel as TwistStamped (the ``use_stamped_velocity`` parameter), as ROS 2 Jazzy's controllers send it."""

RESET_POSITIONS = "reset_positions"
"""The std_srvs/srv/Empty service that puts every robot back at its start pose."""


def registered(name: str, msgtype: str) -> Topic:
    """The registry's topic of that name and type."""
    return next(t for t in (*PUBLISHED, CMD_VEL, CMD_VEL_STAMPED) if (t.name, t.msgtype) == (name, msgtype))


def published(with_map: bool) -> list[Topic]:
    """The topics a node publishes (/map only ``with_map``), world-wide ones and per-robot ones alike."""
    return [t for t in PUBLISHED if with_map or not t.on_request]


def subscribed(stamped: bool) -> list[Topic]:
    """The topics stageros subscribes."""
    return [CMD_VEL_STAMPED if stamped else CMD_VEL]
