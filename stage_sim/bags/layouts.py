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
from typing import TYPE_CHECKING, Any

import numpy as np

from stage_sim.interface import fields
from stage_sim.interface.topics import Endpoint

if TYPE_CHECKING:
    from stage_sim.bags.step_state import PackedScans

HEADER = 4
"""Bytes of the CDR encapsulation header: alignment counts from here."""
_STAMP = struct.Struct("<iI")
_COUNT = struct.Struct("<I")
_POSE = struct.Struct("<dd24xdd")
"""Position x, y, (z; orientation x, y: always 0), orientation z, w."""
_TWIST = struct.Struct("<dd24xd")
"""Linear x, y, (linear z; angular x, y: always 0), angular z."""


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
        self._template = template
        self._buffer = bytearray(template)

    def __reduce__(self) -> tuple[type[Layout], tuple[bytes]]:
        """Pickled as its template (the writer process rebuilds the views into its own buffer)."""
        return type(self), (self._template,)

    @staticmethod
    def prepare(values: Any) -> Any:
        """A step's values as :meth:`refill` reads them, once per step for all endpoints (arrays as lists:
        reading Python floats is cheaper than numpy scalars)."""
        return values

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

    prepare = staticmethod(np.ndarray.tolist)

    def refill(self, values: list[bool], endpoint: Endpoint, sim_time_us: int) -> bytes:
        self._buffer[HEADER] = bool(values[endpoint.robot])
        return bytes(self._buffer)


class OdometryLayout(Layout):
    """nav_msgs/Odometry of a robot (odom, ground truth): stamp, planar pose and velocity; covariances 0."""

    def __init__(self, template: bytes) -> None:
        super().__init__(template)
        self._pose = _aligned(_after_string(template, _after_header(template, HEADER)), 8)
        self._twist = self._pose + (7 + 36) * 8  # after the pose and its covariance

    @staticmethod
    def prepare(values: tuple[np.ndarray, np.ndarray]) -> tuple[list, list]:
        return values[0].tolist(), values[1].tolist()

    def refill(self, values: tuple[list, list], endpoint: Endpoint, sim_time_us: int) -> bytes:
        x, y, yaw = values[0][endpoint.robot]
        vx, vy, vyaw = values[1][endpoint.robot]
        buffer = self._buffer
        _stamp(buffer, HEADER, sim_time_us)
        _POSE.pack_into(buffer, self._pose, x, y, *fields.yaw_quaternion(yaw)[2:])
        _TWIST.pack_into(buffer, self._twist, vx, vy, vyaw)
        return bytes(buffer)


class ScanLayout(Layout):
    """sensor_msgs/LaserScan of a ranger: stamp, ranges and intensities (its geometry and beam count fixed)."""

    def __init__(self, template: bytes) -> None:
        super().__init__(template)
        count = _aligned(_after_header(template, HEADER), 4) + 7 * 4  # after angle_min ... range_max
        self._beams = _COUNT.unpack_from(template, count)[0]
        self._ranges = np.frombuffer(self._buffer, np.float32, self._beams, count + 4)
        self._intensities = np.frombuffer(self._buffer, np.float32, self._beams, count + 8 + 4 * self._beams)

    def refill(self, values: PackedScans, endpoint: Endpoint, sim_time_us: int) -> bytes | None:
        scan = values.measured(endpoint.robot, endpoint.ranger)
        if scan is None:
            return None
        _stamp(self._buffer, HEADER, sim_time_us)
        self._ranges[:], self._intensities[:] = scan  # float32 already, as fields.scan_arrays makes them
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

    prepare = staticmethod(np.ndarray.tolist)

    def refill(self, values: list[list[float]], endpoint: Endpoint, sim_time_us: int) -> bytes:
        buffer = self._buffer
        sec, nanosec = fields.stamp_parts(sim_time_us)
        for at, translation, (x, y, yaw) in zip(self._stamps, self._translations, values, strict=True):
            _STAMP.pack_into(buffer, at, sec, nanosec)
            _POSE.pack_into(buffer, translation, x, y, *fields.yaw_quaternion(yaw)[2:])
        return bytes(buffer)
