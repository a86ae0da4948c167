"""What the simulation needs to know about each robot and each of its lasers, read once from the world.

A robot is a position model (stageros' rule: every position model, indexed in pre-order DFS). Its body is
the polygons of every block in its subtree (the robot's own blocks and those of attached models such as
the laser housing; bitmap bodies traced into blocks as Stage does,
:mod:`stage_sim.maps.body_geometry`), expressed in the robot frame, rasterised at every pose as Stage does
(:mod:`stage_sim.sim.collision`). Its rangers are its rangers by stageros' rule
(:func:`~stage_sim.worldfile.sensor_kinds.robot_sensors`: direct children only), one scan per ranger from its
first sensor, as stageros publishes them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stage_sim.maps.body_geometry import body_polygons, global_poses, transform_points
from stage_sim.sim.drives import DRIVES, Drive
from stage_sim.worldfile.description import Model, Pose, PositionSettings, Sensor, WorldDescription, WorldWarning
from stage_sim.worldfile.errors import SourceLocation
from stage_sim.worldfile.sensor_kinds import robot_sensors


@dataclass(frozen=True)
class RangerSpec:
    """One simulated laser: where it sits on its robot and which beams it casts."""

    name: str
    index: int
    pose: Pose
    sensor: Sensor
    update_interval: float
    ray_offset: tuple[float, float]
    ray_yaw: float
    ray_height: float

    @property
    def beam_angles(self) -> np.ndarray:
        """Beam directions relative to the sensor, counter-clockwise from −fov/2 (Stage's order)."""
        samples = self.sensor.samples
        if samples == 1:
            return np.zeros(1)
        return -self.sensor.fov / 2 + np.arange(samples) * (self.sensor.fov / (samples - 1))


@dataclass(frozen=True)
class RobotSpec:
    """A position model and everything attached to it, as the simulation steps it."""

    index: int
    name: str
    model: Model
    start: tuple[float, float, float]
    settings: PositionSettings
    z_band: tuple[float, float]
    body: tuple[np.ndarray, ...]  #: polygons (M, 2) in the robot frame
    rangers: tuple[RangerSpec, ...]

    @property
    def drive(self) -> Drive:
        """The robot's drive model (its world-file ``drive``)."""
        return DRIVES[self.settings.drive]

    @property
    def radius(self) -> float:
        """Distance from the robot origin to the farthest body vertex (the body's reach as it turns)."""
        return max((float(np.hypot(*p.T).max()) for p in self.body if len(p)), default=0.0)


def build_robots(description: WorldDescription, warnings: list[WorldWarning]) -> list[RobotSpec]:
    """Every position model of the world as a :class:`RobotSpec`, in stageros' robot order."""
    poses = global_poses(description)
    robots = []
    several: dict[SourceLocation | None, list[str]] = {}  # rangers with several sensors, by where they are defined
    for index, model in enumerate(description.robots()):
        pose = poses[id(model)]
        body, z_band = _body(model, pose, poses)
        rangers = tuple(_rangers(model, pose, poses, several))
        settings = model.position or PositionSettings()
        robots.append(
            RobotSpec(index, model.name, model, (pose.x, pose.y, pose.yaw), settings, z_band, body, rangers)
        )
    # One warning per definition, not per robot: a swarm of a thousand must not bury the log.
    for location, messages in several.items():
        more = f" (and {len(messages) - 1} more rangers defined there)" if len(messages) > 1 else ""
        warnings.append(WorldWarning(messages[0] + more, location))
    return robots


def _body(
    robot: Model, robot_pose: Pose, poses: dict[int, Pose]
) -> tuple[tuple[np.ndarray, ...], tuple[float, float]]:
    """Polygons of all bodies in the robot's subtree, in the robot frame, and their joint z band.

    The robot's own polygons are its model-frame ones (``origin`` applied); an attached model's are moved by
    its pose relative to the robot, in one composition where Stage makes two (it may differ by a cell)."""
    polygons, z_low, z_high = [], math.inf, -math.inf
    for model in robot.walk():
        relative = _relative(robot_pose, poses[id(model)])
        for polygon in body_polygons(model):
            points = polygon.points if model is robot else transform_points(polygon.points, relative)
            polygons.append(np.asarray(points, dtype=np.float64))
            z_low = min(z_low, relative.z + polygon.z[0])
            z_high = max(z_high, relative.z + polygon.z[1])
    if not polygons:
        return (), (0.0, 0.0)
    return tuple(polygons), (robot_pose.z + z_low, robot_pose.z + z_high)


def _relative(base: Pose, pose: Pose) -> Pose:
    """``pose`` expressed in the frame ``base`` (both global)."""
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    dx, dy = pose.x - base.x, pose.y - base.y
    return Pose(c * dx + s * dy, -s * dx + c * dy, pose.z - base.z, pose.yaw - base.yaw)


def _rangers(
    robot: Model, robot_pose: Pose, poses: dict[int, Pose], several: dict[SourceLocation | None, list[str]]
) -> list[RangerSpec]:
    """The robot's rangers; those with several sensors are noted in ``several`` (their first is simulated)."""
    rangers = []
    for child in robot_sensors(robot, "ranger"):
        if not child.sensors:
            continue
        if len(child.sensors) > 1:
            several.setdefault(child.location, []).append(
                f"ranger '{child.name}' has {len(child.sensors)} sensors; like stageros only the first is simulated")
        sensor = child.sensors[0]
        ranger_pose = _relative(robot_pose, poses[id(child)])
        # Stage: ray origin = ranger pose ⊕ ranger origin ⊕ sensor pose, raised by half the sensor height.
        ray = ranger_pose.compose(child.origin).compose(sensor.pose)
        rangers.append(RangerSpec(
            name=child.name,
            index=len(rangers),
            # stageros' TF: the ranger's pose in its parent, lifted by the robot's height.
            pose=Pose(child.pose.x, child.pose.y, robot.size[2] + child.pose.z, child.pose.yaw),
            sensor=sensor,
            update_interval=child.update_interval,
            ray_offset=(ray.x, ray.y),
            ray_yaw=ray.yaw,
            ray_height=robot_pose.z + ray.z + sensor.size[2] / 2,
        ))
    return rangers
