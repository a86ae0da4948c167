"""The CDR layout of every message a bag records per step: serialised once, refilled in place, a topic at once.

A message stageros publishes every step changes in a few fields only (the stamp, a pose, the ranges); its
strings (frame ids) and sizes (beams, robots) are fixed for the run. So each endpoint's message is serialised
once by rosbags (the template: :mod:`stage_sim.bags.messages` builds it), and every step writes only the
changing fields into those bytes, at offsets read off the template: no message objects and no serialiser per
message. All endpoints of a topic (100 robots' odometry, their scans), for every step of a batch, share one
buffer (:class:`_Block`), laid out so that a field of every message of the batch is refilled by one numpy
assignment, not a Python call per message and step: the writer process's own Python per message and step
was most of its CPU, with 1 robot as with 100.
tests/bags/test_layouts.py holds the refilled bytes to rosbags' serialisation of the same values, byte for byte.

CDR (little endian, as rosbags writes on this machine): a 4-byte encapsulation header, then each field at an
offset that is a multiple of its size counted from the end of that header; a string is a uint32 length
(with its NUL) and the bytes; a sequence a uint32 count and the elements.
"""

from __future__ import annotations

import math
import struct
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from operator import itemgetter
from typing import TYPE_CHECKING, Any

import numpy as np

from stage_sim.interface import fields
from stage_sim.interface.topics import Endpoint

if TYPE_CHECKING:
    from stage_sim.bags.step_state import PackedScans, ScanRows

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


def _half_turns(yaws: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The z and w of every yaw's quaternion, by :func:`fields.yaw_quaternion`'s own ``math`` calls (numpy's
    sin may differ from the C library's in the last bit: a bag holds what stageros publishes)."""
    halves = (yaws / 2).ravel().tolist()
    return (np.array(list(map(math.sin, halves))).reshape(yaws.shape),
            np.array(list(map(math.cos, halves))).reshape(yaws.shape))


class _Block:
    """The messages of a batch of steps laid end to end in one buffer, the endpoints' messages of each step in
    turn, each starting 4 bytes past a multiple of 8: the end of its encapsulation header, where its CDR
    alignment counts from, falls on the buffer's own 8-byte alignment, so a float64 field of a message is an
    element of the buffer viewed as float64 (and likewise for 4-byte fields)."""

    def __init__(self, templates: Sequence[bytes], steps: int) -> None:
        self.steps = steps
        self.starts: list[int] = []
        at = HEADER
        for template in templates:
            self.starts.append(at)
            at += len(template)
            at += (HEADER - at) % 8
        self.stride = at - HEADER
        """Bytes of a step's messages (a multiple of 8)."""
        self.buffer = bytearray(HEADER + self.stride * steps)
        for step in range(steps):
            for start, template in zip(self.starts, templates, strict=True):
                at = start + step * self.stride
                self.buffer[at:at + len(template)] = template
        self.spans = [(start, start + len(template)) for start, template in zip(self.starts, templates, strict=True)]
        self._every = [(begin + at, end + at) for at in range(0, steps * self.stride, self.stride)
                       for begin, end in self.spans]
        """Every message's span in the buffer, step after step (what :meth:`messages` cuts)."""
        self._cuts: dict[int, Callable[[bytes], Sequence[bytes]]] = {}
        """Per number of steps, what cuts the messages of that many out of the block's bytes."""
        self.f64 = np.frombuffer(self.buffer, "<f8", len(self.buffer) // 8)
        self.f32 = np.frombuffer(self.buffer, "<f4", len(self.buffer) // 4)
        self.i32 = np.frombuffer(self.buffer, "<i4", len(self.buffer) // 4)
        self.u32 = np.frombuffer(self.buffer, "<u4", len(self.buffer) // 4)
        self.u8 = np.frombuffer(self.buffer, np.uint8)

    def index(self, message: Sequence[int], offsets: Sequence[int], size: int) -> np.ndarray:
        """(steps, fields): field i, at byte ``offsets[i]`` of message ``message[i]``, of every step, as an index
        into the buffer's view of ``size``-byte items."""
        first = np.array([(self.starts[k] + offset) // size for k, offset in zip(message, offsets, strict=True)],
                         dtype=np.intp)
        return first[None, :] + (np.arange(self.steps, dtype=np.intp) * (self.stride // size))[:, None]

    def rows32(self, steps: int) -> np.ndarray:
        """(steps, stride / 4): the buffer as float32 from the first step's encapsulation header on, a row per
        step (a field of a step's message at byte ``b`` past its step's start is at column ``b // 4``)."""
        return self.f32[HEADER // 4:HEADER // 4 + steps * self.stride // 4].reshape(steps, self.stride // 4)

    def stamp(self, at: np.ndarray, sim_times_us: np.ndarray) -> None:
        """Write each step's stamp (sec, nanosec) at the 4-byte indices ``at`` (steps, fields)."""
        sec, nanosec = fields.stamp_parts(np.asarray(sim_times_us, dtype=np.int64)[:, None])
        self.i32[at], self.u32[at + 1] = sec, nanosec

    def messages(self, steps: int) -> Sequence[bytes | None]:
        """Every message's bytes as they are now, of the first ``steps`` steps, step after step: the block copied
        once into bytes, then cut by one C call (an itemgetter of every message's slice). A Python loop that
        copied each message straight out of the buffer cost 2.5 times as much, for 1 robot as for 100."""
        if steps not in self._cuts:
            every = [slice(begin, end) for begin, end in self._every[:steps * len(self.spans)]]
            # itemgetter returns a tuple, except of one item
            self._cuts[steps] = itemgetter(*every) if len(every) > 1 else lambda data: (data[every[0]],)
        return self._cuts[steps](bytes(memoryview(self.buffer)[:self._every[steps * len(self.spans) - 1][1]]))


class Layout(ABC):
    """The messages of one per-step topic for each of its recorded endpoints: their template bytes and how a
    batch of steps' values refill them."""

    def __init__(self, templates: Sequence[bytes], endpoints: Sequence[Endpoint]) -> None:
        self._templates, self._endpoints = list(templates), list(endpoints)
        self._robots = np.array([e.robot if e.robot is not None else -1 for e in endpoints], dtype=np.intp)
        self._block = _Block(templates, 0)
        self._fields: dict[str, np.ndarray] = {}

    def __reduce__(self) -> tuple[type[Layout], tuple[list[bytes], list[Endpoint]]]:
        """Pickled as its templates and endpoints (the writer process lays out its own buffer)."""
        return type(self), (self._templates, self._endpoints)

    def _fit(self, steps: int) -> _Block:
        """The block, grown to hold ``steps`` steps (with the fields' indices made again for it)."""
        if steps > self._block.steps:
            self._block = _Block(self._templates, steps)
            self._fields = self._index(self._block)
        return self._block

    def _index(self, block: _Block) -> dict[str, np.ndarray]:
        """The indices of the fields :meth:`refill` writes, per name (steps, fields). Default: every message's
        header stamp (right after the encapsulation header)."""
        every = range(len(self._templates))
        return {"stamp": block.index(every, [HEADER] * len(self._templates), 4)}

    @abstractmethod
    def refill(self, values: Any, sim_times_us: np.ndarray) -> Sequence[bytes | None]:
        """Each endpoint's message bytes for the steps' ``values`` (the topic's :attr:`Topic.values` with a
        leading axis per step), step after step, None for an endpoint that publishes nothing in that step."""

    def count(self, values: Any) -> int:
        """How many messages :meth:`refill` makes of ``values`` (without making them)."""
        return len(self._templates) * len(_steps_of(values))


def _steps_of(values: Any) -> Any:
    """Something as long as the steps of a topic's batch values."""
    return values[0] if isinstance(values, tuple) else values


class ClockLayout(Layout):
    """rosgraph_msgs/Clock: the stamp is the message."""

    def refill(self, values: np.ndarray, sim_times_us: np.ndarray) -> Sequence[bytes | None]:
        steps = len(sim_times_us)
        block = self._fit(steps)
        block.stamp(self._fields["stamp"][:steps], sim_times_us)
        return block.messages(steps)


class BoolLayout(Layout):
    """std_msgs/Bool of a robot (stall): one byte."""

    def _index(self, block: _Block) -> dict[str, np.ndarray]:
        return {"data": block.index(range(len(self._templates)), [HEADER] * len(self._templates), 1)}

    def refill(self, values: np.ndarray, sim_times_us: np.ndarray) -> Sequence[bytes | None]:
        steps = len(sim_times_us)
        block = self._fit(steps)
        block.u8[self._fields["data"][:steps]] = values[:, self._robots]
        return block.messages(steps)


class OdometryLayout(Layout):
    """nav_msgs/Odometry of a robot (odom, ground truth): stamp, planar pose and velocity; covariances 0."""

    def _index(self, block: _Block) -> dict[str, np.ndarray]:
        every = range(len(self._templates))
        poses = [_aligned(_after_string(t, _after_header(t, HEADER)), 8) for t in self._templates]
        return {**super()._index(block), "pose": block.index(every, poses, 8),
                "twist": block.index(every, [pose + (7 + 36) * 8 for pose in poses], 8)}  # after the covariance

    def refill(self, values: tuple[np.ndarray, np.ndarray], sim_times_us: np.ndarray) -> Sequence[bytes | None]:
        steps = len(sim_times_us)
        block = self._fit(steps)
        poses, velocities = values[0][:, self._robots], values[1][:, self._robots]
        f64, pose, twist = block.f64, self._fields["pose"][:steps], self._fields["twist"][:steps]
        block.stamp(self._fields["stamp"][:steps], sim_times_us)
        f64[pose], f64[pose + _Y] = poses[..., 0], poses[..., 1]
        f64[pose + _QZ], f64[pose + _QW] = _half_turns(poses[..., 2])
        f64[twist], f64[twist + _VY], f64[twist + _WZ] = velocities[..., 0], velocities[..., 1], velocities[..., 2]
        return block.messages(steps)


class ScanLayout(Layout):
    """sensor_msgs/LaserScan of a ranger: stamp, ranges and intensities (its geometry and beam count fixed)."""

    def __init__(self, templates: Sequence[bytes], endpoints: Sequence[Endpoint]) -> None:
        super().__init__(templates, endpoints)
        self._counts = [_aligned(_after_header(t, HEADER), 4) + 7 * 4 for t in templates]  # after range_max
        self._beams = [_COUNT.unpack_from(t, count)[0] for t, count in zip(templates, self._counts, strict=True)]
        self._slots = [(e.robot, e.ranger) for e in endpoints]
        self._first_beam = np.cumsum([0, *self._beams]).tolist()
        """Where each endpoint's beams start in the beam indices."""
        self._columns = self._beam_columns()
        self._gather: tuple[tuple[int, ...], tuple[int, ...], np.ndarray | None] | None = None
        """For the last batch's scan layout (first, lengths): the gather index of the endpoints' beams out of a
        step's row (None: the row is the endpoints' beams in order)."""

    def _beam_columns(self) -> list[tuple[int, int, int, int]]:
        """Per endpoint, where its message's ranges and its intensities start in a step's row of float32
        (:meth:`_Block.rows32`), where its beams start in the endpoints' beams end to end, and how many it has."""
        return [((start - HEADER + count + 4) // 4, (start - HEADER + count + 8 + 4 * beams) // 4, first, beams)
                for start, count, first, beams
                in zip(self._block.starts, self._counts, self._first_beam[:-1], self._beams, strict=True)]

    def _in_rows(self, rows: ScanRows) -> np.ndarray | None:
        """Where the endpoints' beams are in a step's row when every ranger measured (None: the row in order)."""
        if self._gather is None or self._gather[:2] != (rows.first, rows.lengths):
            starts = np.cumsum([0, *rows.lengths]).tolist()
            at = [starts[rows.first[robot] + ranger] for robot, ranger in self._slots]
            in_order = at == self._first_beam[:-1] and self._first_beam[-1] == starts[-1]
            gather = None if in_order else np.concatenate(
                [np.arange(start, start + beams) for start, beams in zip(at, self._beams, strict=True)])
            self._gather = (rows.first, rows.lengths, gather)
        return self._gather[2]

    def refill(self, values: ScanRows, sim_times_us: np.ndarray) -> Sequence[bytes | None]:
        steps = len(sim_times_us)
        block = self._fit(steps)
        if not values.measured.all():
            return [data for k, time in enumerate(sim_times_us.tolist())
                    for data in self._refill_step(values.row(k), k, time)]
        gather = self._in_rows(values)
        ranges, intensities = (values.ranges, values.intensities) if gather is None else (
            values.ranges[:, gather], values.intensities[:, gather])
        block.stamp(self._fields["stamp"][:steps], sim_times_us)
        rows = block.rows32(steps)
        for in_ranges, in_intensities, first, beams in self._columns:  # a slice each: an index of every beam, 3.5 x
            rows[:, in_ranges:in_ranges + beams] = ranges[:, first:first + beams]
            rows[:, in_intensities:in_intensities + beams] = intensities[:, first:first + beams]
        return block.messages(steps)

    def _refill_step(self, scans: PackedScans, step: int, sim_time_us: int) -> Sequence[bytes | None]:
        """One step in which some rangers took no scan (they are slower than the step): those that did, one by
        one."""
        block, out = self._block, []
        first, offsets, row = scans.first, scans.offsets, self._block.rows32(step + 1)[step]
        for k, (robot, ranger) in enumerate(self._slots):
            start = offsets[first[robot] + ranger]
            if start < 0:
                out.append(None)
                continue
            in_ranges, in_intensities, _, beams = self._columns[k]
            block.stamp(self._fields["stamp"][step:step + 1, k:k + 1], np.array([sim_time_us]))
            row[in_ranges:in_ranges + beams] = scans.ranges[start:start + beams]
            row[in_intensities:in_intensities + beams] = scans.intensities[start:start + beams]
            begin, end = block.spans[k]
            at = step * block.stride
            out.append(bytes(memoryview(block.buffer)[begin + at:end + at]))
        return out

    def count(self, values: ScanRows) -> int:
        measured = values.measured[:, [values.first[robot] + ranger for robot, ranger in self._slots]]
        return int(np.count_nonzero(measured))


class TransformsLayout(Layout):
    """tf2_msgs/TFMessage of every robot's odom → base_footprint: per transform, stamp, x, y and yaw."""

    def _index(self, block: _Block) -> dict[str, np.ndarray]:
        message, stamps, translations = [], [], []
        for k, template in enumerate(self._templates):
            offset = HEADER + 4  # after the sequence count
            for _ in range(_COUNT.unpack_from(template, HEADER)[0]):
                message.append(k)
                stamps.append(_aligned(offset, 4))
                translation = _aligned(_after_string(template, _after_header(template, offset)), 8)
                translations.append(translation)
                offset = translation + 7 * 8
        return {"stamp": block.index(message, stamps, 4), "translation": block.index(message, translations, 8)}

    def refill(self, values: np.ndarray, sim_times_us: np.ndarray) -> Sequence[bytes | None]:
        steps = len(sim_times_us)
        block = self._fit(steps)
        poses = np.tile(values, (1, len(self._templates), 1))  # every message holds every robot's
        f64, at = block.f64, self._fields["translation"][:steps]
        block.stamp(self._fields["stamp"][:steps], sim_times_us)
        f64[at], f64[at + _Y] = poses[..., 0], poses[..., 1]
        f64[at + _QZ], f64[at + _QW] = _half_turns(poses[..., 2])
        return block.messages(steps)
