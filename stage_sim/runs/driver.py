"""The wander strategy driving a :class:`Simulation` directly, without ROS: one :class:`Wanderer` per robot
that has a laser, deciding on each step's scan and odometry like the ``wander`` node does over topics.

Used by ``stage_sim render --controller wander`` and by tests and tuning runs that need thousands of sim
seconds quickly; the launch scripts run the same strategy through the real nodes.
"""

from __future__ import annotations

from dataclasses import replace

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
                settings = replace(base, holonomic=robot.settings.drive == "omni")
                self.wanderers[robot.index] = Wanderer(settings, wanderer_seed(seed, robot.index))

    def reading(self, robot: int) -> LaserReading:
        """The robot's first laser's latest scan as the wanderer sees it."""
        ranger = self.sim.robots[robot].rangers[0]
        sensor = ranger.sensor
        return LaserReading(
            self.sim.scans[robot][0].ranges, -sensor.fov / 2, sensor.fov / max(sensor.samples - 1, 1),
            sensor.range_min, sensor.range_max, (*ranger.ray_offset, ranger.ray_yaw),
        )

    def decide(self) -> None:
        """Set each driven robot's velocity from its current scan and odometry."""
        sim = self.sim
        for robot, wanderer in self.wanderers.items():
            pose = tuple(float(v) for v in sim.odometry_poses[robot])
            sim.set_velocity(robot, *wanderer.decide(self.reading(robot), sim.sim_time, pose))
