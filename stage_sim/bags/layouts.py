"""The CDR layout of every message a bag records per step: serialised once, refilled in place.

A message stageros publishes every step changes in a few fields only (the stamp, a pose, the ranges); its
strings (frame ids) and sizes (beams, robots) are fixed for the run. So each endpoint's message is serialised
once by rosbags (the template: :mod:`stage_sim.bags.messages` builds it) and every step writes only the
changing fields into a copy of those bytes, at offsets read off the template: no message objects and no
serialiser per message, the writer thread's main cost with 100 robots. tests/bags/test_layouts.py holds the
refilled bytes to rosbags' serialisation of the same values, byte for byte.

CDR (little endian, as rosbags writes on this machine): a 4-byte encapsulation header, then each field at an
offset that is a multiple of its size counted from the end of that header; a string is a uint32 length
(with its NUL) and the bytes; a sequence a uint32 count and the elements.
"""

from __future__ import annotations

import struct
from abc import ABC, abstractmethod
from typing import Any

import numpy as np

from stage_sim.interface import fields
from stage_sim.interface.topics import Endpoint

HEADER = 4
"""Bytes of the CDR encapsulation header: alignment counts from here."""
_STAMP = struct.Struct("<iI")
_TWO = struct.Struct("<dd")
_COUNT = struct.Struct("<I")


def _aligned(offset: int, size: int) -> int:
    """``offset`` moved up to the next multiple of ``size`` past the encapsulation header."""
    return HEADER + -(-(offset - HEADER) // size) * size


def _after_string(data: bytes, offset: int) -> int:
    """The offset just after the string whose length field is at (or aligned after) ``offset``."""
    offset = _aligned(offset, 4)
    return offset + 4 + _COUNT.unpack_from(data, offset)[0]


def _after_header(data: bytes, offset: int) -> int:
    """The offset just after a std_msgs/Header (stamp, frame_id) starting at ``offset``."""
    return _after_string(data, _aligned(offset, 4) + _STAMP.size)


def _stamp(buffer: bytearray, offset: int, sim_time_us: int) -> None:
    _STAMP.pack_into(buffer, offset, *fields.stamp_parts(sim_time_us))


class Layout(ABC):
    """One endpoint's message: its template bytes and how a step's values refill them."""

    def __init__(self, template: bytes) -> None:
        self._buffer = bytearray(template)

    @abstractmethod
    def refill(self, values: Any, endpoint: Endpoint, sim_time_us: int) -> bytes | None:
        """The message's bytes for this step's ``values`` (the topic's :attr:`Topic.values`), None for none."""


class ClockLayout(Layout):
    """rosgraph_msgs/Clock: the stamp is the message."""

    def refill(self, values: int, endpoint: Endpoint, sim_time_us: int) -> bytes:
        _stamp(self._buffer, HEADER, sim_time_us)
        return bytes(self._buffer)


class BoolLayout(Layout):
    """std_msgs/Bool of a robot (stall): one byte."""

    def refill(self, values: np.ndarray, endpoint: Endpoint, sim_time_us: int) -> bytes:
        self._buffer[HEADER] = bool(values[endpoint.robot])
        return bytes(self._buffer)


class OdometryLayout(Layout):
    """nav_msgs/Odometry of a robot (odom, ground truth): stamp, planar pose and velocity; covariances 0."""

    def __init__(self, template: bytes) -> None:
        super().__init__(template)
        pose = _aligned(_after_string(template, _after_header(template, HEADER)), 8)
        self._position, self._orientation = pose, pose + 5 * 8  # position x, y; orientation z, w
        twist = pose + (7 + 36) * 8  # after the pose and its covariance
        self._linear, self._angular = twist, twist + 5 * 8

    def refill(self, values: tuple[np.ndarray, np.ndarray], endpoint: Endpoint, sim_time_us: int) -> bytes:
        poses, velocities = values
        x, y, yaw = poses[endpoint.robot]
        vx, vy, vyaw = velocities[endpoint.robot]
        buffer = self._buffer
        _stamp(buffer, HEADER, sim_time_us)
        _TWO.pack_into(buffer, self._position, x, y)
        _TWO.pack_into(buffer, self._orientation, *fields.yaw_quaternion(float(yaw))[2:])
        _TWO.pack_into(buffer, self._linear, vx, vy)
        struct.pack_into("<d", buffer, self._angular, vyaw)
        return bytes(buffer)


class ScanLayout(Layout):
    """sensor_msgs/LaserScan of a ranger: stamp, ranges and intensities (its geometry and beam count fixed)."""

    def __init__(self, template: bytes) -> None:
        super().__init__(template)
        count = _aligned(_after_header(template, HEADER), 4) + 7 * 4  # after angle_min ... range_max
        self._beams = _COUNT.unpack_from(template, count)[0]
        self._ranges = np.frombuffer(self._buffer, np.float32, self._beams, count + 4)
        self._intensities = np.frombuffer(self._buffer, np.float32, self._beams, count + 8 + 4 * self._beams)

    def refill(self, values: fields.LatestScans, endpoint: Endpoint, sim_time_us: int) -> bytes | None:
        scan = values.measured(endpoint.robot, endpoint.ranger)
        if scan is None:
            return None
        _stamp(self._buffer, HEADER, sim_time_us)
        self._ranges[:] = scan.ranges  # cast to float32 as fields.scan_arrays does
        self._intensities[:] = scan.intensities
        return bytes(self._buffer)


class TransformsLayout(Layout):
    """tf2_msgs/TFMessage of every robot's odom → base_footprint: per transform, stamp, x, y and yaw."""

    def __init__(self, template: bytes) -> None:
        super().__init__(template)
        self._stamps, self._translations = [], []
        offset = HEADER + 4  # after the sequence count
        for _ in range(_COUNT.unpack_from(template, HEADER)[0]):
            self._stamps.append(_aligned(offset, 4))
            translation = _aligned(_after_string(template, _after_header(template, offset)), 8)
            self._translations.append(translation)
            offset = translation + 7 * 8

    def refill(self, values: np.ndarray, endpoint: Endpoint, sim_time_us: int) -> bytes:
        buffer = self._buffer
        stamp = fields.stamp_parts(sim_time_us)
        for at, translation, (x, y, yaw) in zip(self._stamps, self._translations, values.tolist(), strict=True):
            _STAMP.pack_into(buffer, at, *stamp)
            _TWO.pack_into(buffer, translation, x, y)
            _TWO.pack_into(buffer, translation + 5 * 8, *fields.yaw_quaternion(yaw)[2:])
        return bytes(buffer)
