"""The CDR layout of every message a bag records per step: serialised once, refilled in place, a topic at once.

A message stageros publishes every step changes in a few fields only (the stamp, a pose, the ranges); its
strings (frame ids) and sizes (beams, robots) are fixed for the run. So each endpoint's message is serialised
once by rosbags (the template: :mod:`stage_sim.bags.messages` builds it), and every step writes only the
changing fields into those bytes, at offsets read off the template: no message objects and no serialiser per
message. All endpoints of a topic (100 robots' odometry, their scans) share one buffer (:class:`_Block`), laid
out so that each field of every message is refilled by one numpy assignment per step, not a Python call per
message: with 100 robots the writer process's own Python per message was most of its CPU.
tests/bags/test_layouts.py holds the refilled bytes to rosbags' serialisation of the same values, byte for byte.

CDR (little endian, as rosbags writes on this machine): a 4-byte encapsulation header, then each field at an
offset that is a multiple of its size counted from the end of that header; a string is a uint32 length
(with its NUL) and the bytes; a sequence a uint32 count and the elements.
"""

from __future__ import annotations

import math
import struct
from abc import ABC, abstractmethod
from collections.abc import Sequence
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
# Doubles after a pose's (or transform's) first field: position x, y, z, then orientation x, y, z, w.
_Y, _QZ, _QW = 1, 5, 6
# Doubles after a twist's first field: linear x, y, z, then angular x, y, z.
_VY, _WZ = 1, 5


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


def _half_turns(yaws: np.ndarray) -> tuple[list[float], list[float]]:
    """The z and w of every yaw's quaternion, by :func:`fields.yaw_quaternion`'s own ``math`` calls (numpy's
    sin may differ from the C library's in the last bit: a bag holds what stageros publishes)."""
    halves = (yaws / 2).tolist()
    return list(map(math.sin, halves)), list(map(math.cos, halves))


class _Block:
    """Messages laid end to end in one buffer, each starting 4 bytes past a multiple of 8: the end of its
    encapsulation header, where its CDR alignment counts from, falls on the buffer's own 8-byte alignment, so a
    float64 field of a message is an element of the buffer viewed as float64 (and likewise for 4-byte fields)."""

    def __init__(self, templates: Sequence[bytes]) -> None:
        self.starts: list[int] = []
        at = HEADER
        for template in templates:
            self.starts.append(at)
            at += len(template)
            at += (HEADER - at) % 8
        self.buffer = bytearray(at)
        for start, template in zip(self.starts, templates, strict=True):
            self.buffer[start:start + len(template)] = template
        self.spans = [(start, start + len(template)) for start, template in zip(self.starts, templates, strict=True)]
        self.f64 = np.frombuffer(self.buffer, "<f8", len(self.buffer) // 8)
        self.f32 = np.frombuffer(self.buffer, "<f4", len(self.buffer) // 4)
        self.i32 = np.frombuffer(self.buffer, "<i4", len(self.buffer) // 4)
        self.u32 = np.frombuffer(self.buffer, "<u4", len(self.buffer) // 4)
        self.u8 = np.frombuffer(self.buffer, np.uint8)

    def index(self, offsets: Sequence[int], size: int) -> np.ndarray:
        """Message k's field at byte ``offsets[k]`` as an index into the buffer's view of ``size``-byte items."""
        return np.array([(start + offset) // size for start, offset in zip(self.starts, offsets, strict=True)],
                        dtype=np.intp)

    def stamp(self, at: np.ndarray, sim_time_us: int) -> None:
        """Write the stamp (sec, nanosec) at the 4-byte indices ``at``."""
        sec, nanosec = fields.stamp_parts(sim_time_us)
        self.i32[at] = sec
        self.u32[at + 1] = nanosec

    def messages(self) -> list[bytes]:
        """Every message's bytes as they are now."""
        data = bytes(self.buffer)
        return [data[start:end] for start, end in self.spans]


class Layout(ABC):
    """The messages of one per-step topic for each of its recorded endpoints: their template bytes and how a
    step's values refill them."""

    def __init__(self, templates: Sequence[bytes], endpoints: Sequence[Endpoint]) -> None:
        self._templates, self._endpoints = list(templates), list(endpoints)
        self._block = _Block(templates)
        self._robots = np.array([e.robot if e.robot is not None else -1 for e in endpoints], dtype=np.intp)

    def __reduce__(self) -> tuple[type[Layout], tuple[list[bytes], list[Endpoint]]]:
        """Pickled as its templates and endpoints (the writer process lays out its own buffer)."""
        return type(self), (self._templates, self._endpoints)

    def _header_stamps(self) -> np.ndarray:
        """The index of every message's header stamp (right after the encapsulation header)."""
        return self._block.index([HEADER] * len(self._templates), 4)

    @abstractmethod
    def refill(self, values: Any, sim_time_us: int) -> list[bytes | None]:
        """Each endpoint's message bytes for this step's ``values`` (the topic's :attr:`Topic.values`), None
        for an endpoint that publishes nothing this step."""

    def count(self, values: Any) -> int:
        """How many messages :meth:`refill` makes of ``values`` (without making them)."""
        return len(self._templates)


class ClockLayout(Layout):
    """rosgraph_msgs/Clock: the stamp is the message."""

    def __init__(self, templates: Sequence[bytes], endpoints: Sequence[Endpoint]) -> None:
        super().__init__(templates, endpoints)
        self._stamps = self._header_stamps()

    def refill(self, values: int, sim_time_us: int) -> list[bytes | None]:
        self._block.stamp(self._stamps, sim_time_us)
        return self._block.messages()


class BoolLayout(Layout):
    """std_msgs/Bool of a robot (stall): one byte."""

    def __init__(self, templates: Sequence[bytes], endpoints: Sequence[Endpoint]) -> None:
        super().__init__(templates, endpoints)
        self._data = self._block.index([HEADER] * len(templates), 1)

    def refill(self, values: np.ndarray, sim_time_us: int) -> list[bytes | None]:
        self._block.u8[self._data] = values[self._robots]
        return self._block.messages()


class OdometryLayout(Layout):
    """nav_msgs/Odometry of a robot (odom, ground truth): stamp, planar pose and velocity; covariances 0."""

    def __init__(self, templates: Sequence[bytes], endpoints: Sequence[Endpoint]) -> None:
        super().__init__(templates, endpoints)
        self._stamps = self._header_stamps()
        poses = [_aligned(_after_string(t, _after_header(t, HEADER)), 8) for t in templates]
        self._pose = self._block.index(poses, 8)
        self._twist = self._block.index([pose + (7 + 36) * 8 for pose in poses], 8)  # after pose and covariance

    def refill(self, values: tuple[np.ndarray, np.ndarray], sim_time_us: int) -> list[bytes | None]:
        poses, velocities = values[0][self._robots], values[1][self._robots]
        f64, pose, twist = self._block.f64, self._pose, self._twist
        self._block.stamp(self._stamps, sim_time_us)
        f64[pose], f64[pose + _Y] = poses[:, 0], poses[:, 1]
        f64[pose + _QZ], f64[pose + _QW] = _half_turns(poses[:, 2])
        f64[twist], f64[twist + _VY], f64[twist + _WZ] = velocities[:, 0], velocities[:, 1], velocities[:, 2]
        return self._block.messages()


class ScanLayout(Layout):
    """sensor_msgs/LaserScan of a ranger: stamp, ranges and intensities (its geometry and beam count fixed)."""

    def __init__(self, templates: Sequence[bytes], endpoints: Sequence[Endpoint]) -> None:
        super().__init__(templates, endpoints)
        self._stamps = self._header_stamps()
        counts = [_aligned(_after_header(t, HEADER), 4) + 7 * 4 for t in templates]  # after angle_min ... range_max
        self._beams = [_COUNT.unpack_from(t, count)[0] for t, count in zip(templates, counts, strict=True)]
        self._slots = [(e.robot, e.ranger) for e in endpoints]
        self._first_beam = np.cumsum([0, *self._beams]).tolist()
        """Where each endpoint's beams start in the index arrays below."""
        self._ranges = self._beam_index([count + 4 for count in counts])
        self._intensities = self._beam_index([count + 8 + 4 * beams for count, beams in zip(counts, self._beams,
                                                                                               strict=True)])
        self._source: tuple[list[int], np.ndarray | None] = ([], None)
        """The scans' positions in the last step's packed arrays, and the gather index they make (None: the
        packed arrays are the endpoints' beams in order)."""

    def _beam_index(self, offsets: list[int]) -> np.ndarray:
        """The float32 indices of every message's beams from its first at ``offsets``, end to end."""
        firsts = self._block.index(offsets, 4)
        return np.concatenate([np.arange(first, first + beams) for first, beams in zip(firsts, self._beams,
                                                                                         strict=True)])

    def _starts(self, values: PackedScans) -> list[int]:
        """Where each endpoint's scan starts in the step's packed arrays (-1: it took none)."""
        first, offsets = values.first, values.offsets
        return [offsets[first[robot] + ranger] for robot, ranger in self._slots]

    def refill(self, values: PackedScans, sim_time_us: int) -> list[bytes | None]:
        starts = self._starts(values)
        if -1 in starts:
            return self._refill_measured(values, starts, sim_time_us)
        if starts != self._source[0]:
            in_order = starts == self._first_beam[:-1] and self._first_beam[-1] == len(values.ranges)
            gather = None if in_order else np.concatenate(
                [np.arange(start, start + beams) for start, beams in zip(starts, self._beams, strict=True)])
            self._source = (starts, gather)
        gather = self._source[1]
        block = self._block
        block.stamp(self._stamps, sim_time_us)
        if gather is None:
            block.f32[self._ranges], block.f32[self._intensities] = values.ranges, values.intensities
        else:
            block.f32[self._ranges], block.f32[self._intensities] = values.ranges[gather], values.intensities[gather]
        return block.messages()

    def _refill_measured(self, values: PackedScans, starts: list[int], sim_time_us: int) -> list[bytes | None]:
        """A step in which some rangers took no scan (they are slower than the step): those that did, one by
        one."""
        block, out = self._block, []
        for k, (start, beams) in enumerate(zip(starts, self._beams, strict=True)):
            if start < 0:
                out.append(None)
                continue
            beam = slice(self._first_beam[k], self._first_beam[k] + beams)
            block.stamp(self._stamps[k:k + 1], sim_time_us)
            block.f32[self._ranges[beam]] = values.ranges[start:start + beams]
            block.f32[self._intensities[beam]] = values.intensities[start:start + beams]
            begin, end = block.spans[k]
            out.append(bytes(block.buffer[begin:end]))
        return out

    def count(self, values: PackedScans) -> int:
        return sum(start >= 0 for start in self._starts(values))


class TransformsLayout(Layout):
    """tf2_msgs/TFMessage of every robot's odom → base_footprint: per transform, stamp, x, y and yaw."""

    def __init__(self, templates: Sequence[bytes], endpoints: Sequence[Endpoint]) -> None:
        super().__init__(templates, endpoints)
        stamps, translations = [], []
        for start, template in zip(self._block.starts, templates, strict=True):
            offset = HEADER + 4  # after the sequence count
            for _ in range(_COUNT.unpack_from(template, HEADER)[0]):
                stamps.append((start + _aligned(offset, 4)) // 4)
                translation = _aligned(_after_string(template, _after_header(template, offset)), 8)
                translations.append((start + translation) // 8)
                offset = translation + 7 * 8
        self._stamps = np.array(stamps, dtype=np.intp)
        self._translations = np.array(translations, dtype=np.intp)
        self._copies = len(templates)

    def refill(self, values: np.ndarray, sim_time_us: int) -> list[bytes | None]:
        poses = values if self._copies == 1 else np.tile(values, (self._copies, 1))
        f64, at = self._block.f64, self._translations
        self._block.stamp(self._stamps, sim_time_us)
        f64[at], f64[at + _Y] = poses[:, 0], poses[:, 1]
        f64[at + _QZ], f64[at + _QW] = _half_turns(poses[:, 2])
        return self._block.messages()
