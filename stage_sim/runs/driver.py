"""The wander strategy driving a :class:`Simulation` directly, without ROS: one :class:`Wanderer` per robot
that has a laser, deciding on each step's scan and odometry like the ``wander`` node does over topics.

Used by ``stage_sim render --controller wander`` and by tests and tuning runs that need thousands of sim
seconds quickly; the launch scripts run the same strategy through the real nodes.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from stage_sim.sim.simulation import Simulation
from stage_sim.wander.config import WanderConfig
from stage_sim.wander.laser_reading import LaserReading
from stage_sim.wander.reactive import Wanderer


def wanderer_seed(seed: int | None, robot: int) -> int | None:
    """The seed of one robot's wanderer in a run seeded with ``seed`` (None: unseeded)."""
    return None if seed is None else seed * 100 + robot


class WanderDriver:
    """Commands every laser-equipped robot of ``sim`` with its own wanderer; call :meth:`decide` before each step.

    ``config`` overrides the defaults (``holonomic`` is set per robot from its drive); robots without a laser
    are left alone.
    """

    def __init__(self, sim: Simulation, seed: int | None = None, config: WanderConfig | None = None) -> None:
        self.sim = sim
        base = config or WanderConfig()
        self.wanderers: dict[int, Wanderer] = {}
        for robot in sim.robots:
            if robot.rangers:
                settings = replace(base, holonomic=robot.drive.holonomic)
                self.wanderers[robot.index] = Wanderer(settings, wanderer_seed(seed, robot.index))

    def reading(self, robot: int) -> LaserReading:
        """The robot's first laser's latest scan as the ``wander`` node receives it from stageros: the
        LaserScan's float32 angle and range fields, and the laser's mounting as /tf_static gives it (the
        ranger's pose, its yaw through a quaternion). Anything else would make the core's runs differ from the
        ROS sessions' in the last bits, enough for a long run to take another path; a miss in particular
        reads float32(range_max), which only the float32 range_max recognises as a miss."""
        ranger = self.sim.robots[robot].rangers[0]
        sensor, mount = ranger.sensor, ranger.pose
        increment = sensor.fov / (sensor.samples - 1) if sensor.samples > 1 else 0.0
        return LaserReading(
            self.sim.scans[robot][0].ranges, _float32(-sensor.fov / 2), _float32(increment),
            _float32(sensor.range_min), _float32(sensor.range_max), (mount.x, mount.y, through_quaternion(mount.yaw)),
        )

    def decide(self) -> None:
        """Set each driven robot's velocity from its current scan and odometry (its yaw as an Odometry
        message carries it)."""
        sim = self.sim
        for robot, wanderer in self.wanderers.items():
            x, y, yaw = (float(v) for v in sim.odometry_poses[robot])
            pose = (x, y, through_quaternion(yaw))
            sim.set_velocity(robot, *wanderer.decide(self.reading(robot), sim.sim_time, pose,
                                                     bool(sim.stalled[robot])))


def _float32(value: float) -> float:
    """A value as a float32 message field carries it."""
    return float(np.float32(value))


def through_quaternion(yaw: float) -> float:
    """A yaw after the trip through a ROS quaternion: stageros sends (0, 0, sin(yaw/2), cos(yaw/2)) and the
    ``wander`` node reads it back with atan2, which may differ from ``yaw`` in the last bit."""
    x = y = 0.0
    z, w = math.sin(yaw / 2), math.cos(yaw / 2)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
