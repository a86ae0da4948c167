"""The values stageros puts in its messages, computed from a simulation without ROS.

One description serves both writers of those messages: :mod:`stage_sim.ros.conversions` fills rclpy
messages with these values and :mod:`stage_sim.bags.messages` fills the serialisation library's classes
with the same ones, so a bag recorded without ROS holds what stageros publishes, field for field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from stage_sim.sim.rangers import MeasuredBeams, Scan
    from stage_sim.sim.robots import RangerSpec
    from stage_sim.sim.simulation import Simulation


MICROSECONDS = 1_000_000
"""Microseconds a second: the simulation counts its time in integer microseconds."""


def stamp_parts(sim_time_us: int) -> tuple[int, int]:
    """(sec, nanosec) of a sim time in integer microseconds: exact, no float rounding (also of an int64 array
    of them, element by element)."""
    return sim_time_us // MICROSECONDS, (sim_time_us % MICROSECONDS) * 1000


def stamp_ns(sim_time_us: int) -> int:
    """A sim time in integer nanoseconds (bag log times)."""
    return sim_time_us * 1000


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation about z by ``yaw`` radians."""
    return 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)


@dataclass(frozen=True)
class ScanGeometry:
    """The LaserScan fields that never change for a ranger: CCW from −fov/2, its range limits."""

    angle_min: float
    angle_max: float
    angle_increment: float
    time_increment: float
    scan_time: float
    range_min: float
    range_max: float


def scan_geometry(ranger: RangerSpec) -> ScanGeometry:
    """A ranger's constant LaserScan fields (one sample: increment 0)."""
    sensor = ranger.sensor
    return ScanGeometry(
        angle_min=-sensor.fov / 2,
        angle_max=sensor.fov / 2,
        angle_increment=sensor.fov / (sensor.samples - 1) if sensor.samples > 1 else 0.0,
        time_increment=0.0,
        scan_time=ranger.update_interval,
        range_min=sensor.range_min,
        range_max=sensor.range_max,
    )


def scan_arrays(scan: Scan) -> tuple[np.ndarray, np.ndarray]:
    """Ranges and intensities as the float32 arrays of a LaserScan (a miss reads exactly range_max)."""
    return scan.ranges.astype(np.float32), scan.intensities.astype(np.float32)




class LatestScans(NamedTuple):
    """Every ranger's latest scan (``scans[robot][ranger]``) and the step's sim time: a ranger publishes only
    in the steps it measured in (rangers slower than interval_sim skip steps). A named tuple: stageros and a
    recording make one every step, and a frozen dataclass costs a microsecond to make."""

    scans: list[list[Scan]]
    time: float
    beams: MeasuredBeams | None = None
    """The beams the scans are views of, every ranger's end to end (:attr:`Simulation.measured_beams`)."""

    def measured(self, robot: int, ranger: int) -> Scan | None:
        """The scan ranger ``ranger`` of robot ``robot`` took in this step, None if it took none."""
        scan = self.scans[robot][ranger]
        return scan if scan.stamp == self.time else None

    def snapshot(self) -> LatestScans:
        """The same step's measurements, safe to keep after the simulation steps on (scans are never changed,
        only replaced: copying the lists is enough)."""
        return LatestScans([list(robot) for robot in self.scans], self.time, self.beams)


def latest_scans(sim: Simulation) -> LatestScans:
    """The scans of the step just taken."""
    return LatestScans(sim.scans, sim.sim_time, sim.measured_beams)
