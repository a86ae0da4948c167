"""What steps published, copied off the simulation: what the stepping side hands the bag writer process.

The stepping side keeps each step's quantities (:class:`~stage_sim.interface.topics.Quantity`) in a
:class:`StepBatch` by reference, one attribute lookup a step. The simulation never writes an array it has
exposed (it replaces it), so the references still hold the step's values when the batch is handed over
(:meth:`StepBatch.settle`): each quantity's steps are then copied into its column in one C call (one
preallocated array per quantity, a row per step), about 1 µs a step in all. All of a batch's columns are views
of one buffer, laid out the same way in every batch of a recording (:class:`BatchLayout`, which the writer learns
once): the buffer is a slot of memory the writer process shares (:mod:`stage_sim.bags.slots`), which reads the
steps where they were copied, with no pickling and no pipe to carry them. The writer derives each topic's values
for all the batch's steps at once (:meth:`StepBatch.values`).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from operator import attrgetter
from typing import TYPE_CHECKING, Any

import numpy as np

from stage_sim.interface import fields
from stage_sim.interface.topics import SIM_TIME_US, Quantity, StepValues, Topic

if TYPE_CHECKING:
    from stage_sim.sim.rangers import MeasuredBeams
    from stage_sim.sim.simulation import Simulation


@dataclass(frozen=True)
class PackedScans:
    """The scans one step measured, every ranger's beams end to end: ``measured(robot, ranger)`` answers as
    :class:`fields.LatestScans` does, with (ranges, intensities) float32 views."""

    first: tuple[int, ...]
    """(robots + 1,) index of each robot's first ranger in ``offsets``."""
    offsets: list[int]
    """Where each ranger's beams start in the arrays; -1: it took no scan this step."""
    lengths: tuple[int, ...]
    ranges: np.ndarray
    intensities: np.ndarray

    def measured(self, robot: int, ranger: int) -> tuple[np.ndarray, np.ndarray] | None:
        """The ranges and intensities ranger ``ranger`` of robot ``robot`` took in this step, None if none."""
        k = self.first[robot] + ranger
        start = self.offsets[k]
        if start < 0:
            return None
        end = start + self.lengths[k]
        return self.ranges[start:end], self.intensities[start:end]


@dataclass(frozen=True)
class ScanRows:
    """The scans of a batch of steps: per step (row), the beams of every ranger that measured, end to end, and
    which rangers measured."""

    first: tuple[int, ...]
    """(robots + 1,) index of each robot's first ranger in ``lengths``."""
    lengths: tuple[int, ...]
    ranges: np.ndarray
    """float32 (steps, beams of all rangers)."""
    intensities: np.ndarray
    measured: np.ndarray
    """bool (steps, rangers)."""

    def row(self, k: int) -> PackedScans:
        """Step ``k``'s scans."""
        offsets, at = [], 0
        for measured, length in zip(self.measured[k].tolist(), self.lengths, strict=True):
            offsets.append(at if measured else -1)
            at += length if measured else 0
        return PackedScans(self.first, offsets, self.lengths, self.ranges[k], self.intensities[k])


class _Column(ABC):
    """One value of a per-step topic, for the steps of a batch: a row per step, in arrays that are views of the
    batch's buffer."""

    @abstractmethod
    def arrays(self) -> tuple[np.ndarray, ...]:
        """Its arrays, a row per step (the batch's layout places them in its buffer)."""

    @abstractmethod
    def on(self, arrays: Sequence[np.ndarray]) -> _Column:
        """A column like this one over ``arrays``, shaped like :meth:`arrays` but for another number of rows."""

    @abstractmethod
    def pack(self, kept: Sequence[Any], seconds: Sequence[float], start: int) -> None:
        """Copy the values ``kept`` of some steps (taken at sim times ``seconds``) into the rows from ``start`` on."""

    @abstractmethod
    def rows(self, count: int) -> Any:
        """The first ``count`` steps' values at once, a leading axis per step: what a topic's layout reads."""


class _Array(_Column):
    """An array value (poses, velocities, stall flags) or a number (the sim time)."""

    def __init__(self, data: np.ndarray) -> None:
        self.data = data

    @classmethod
    def like(cls, value: Any) -> _Array:
        """An empty column for values like ``value``."""
        value = np.asarray(value)
        return cls(np.empty((0, *value.shape), value.dtype))

    def arrays(self) -> tuple[np.ndarray, ...]:
        return (self.data,)

    def on(self, arrays: Sequence[np.ndarray]) -> _Array:
        return _Array(*arrays)

    def pack(self, kept: Sequence[Any], seconds: Sequence[float], start: int) -> None:
        rows = self.data[start:start + len(kept)]
        if rows.ndim == 1:  # numbers
            rows[:] = kept
        else:  # arrays of one shape, end to end
            _copy_rows(kept, rows)

    def rows(self, count: int) -> np.ndarray:
        return self.data[:count]


class _Scans(_Column):
    """The scans a step measured, packed: the measured rangers' beams end to end in one row, and which rangers
    measured. Kept of a step: the simulation's :class:`~stage_sim.sim.rangers.MeasuredBeams` (None before any)."""

    def __init__(self, first: tuple[int, ...], lengths: tuple[int, ...], ranges: np.ndarray,
                 intensities: np.ndarray, measured: np.ndarray) -> None:
        self.first, self.lengths = first, lengths
        self.ranges, self.intensities, self.measured = ranges, intensities, measured

    @classmethod
    def empty(cls, first: tuple[int, ...], lengths: tuple[int, ...]) -> _Scans:
        """An empty column for the scans of rangers of ``lengths`` beams."""
        beams = sum(lengths)
        return cls(first, lengths, np.empty((0, beams), np.float32), np.empty((0, beams), np.float32),
                   np.empty((0, len(lengths)), bool))

    def arrays(self) -> tuple[np.ndarray, ...]:
        return self.ranges, self.intensities, self.measured

    def on(self, arrays: Sequence[np.ndarray]) -> _Scans:
        return _Scans(self.first, self.lengths, *arrays)

    def pack(self, kept: Sequence[MeasuredBeams | None], seconds: Sequence[float], start: int) -> None:
        end = start + len(kept)
        if all(beams is not None and beams.time == time and beams.due is None
               for beams, time in zip(kept, seconds, strict=True)):  # every ranger measured in every step
            _copy_rows([beams.ranges for beams in kept], self.ranges[start:end])
            _copy_rows([beams.intensities for beams in kept], self.intensities[start:end])
            self.measured[start:end] = True
            return
        for k, beams, time in zip(range(start, end), kept, seconds, strict=True):
            self._put(k, beams, time)

    def _put(self, k: int, beams: MeasuredBeams | None, time: float) -> None:
        """Copy the beams measured at ``time`` into row ``k``."""
        if beams is None or beams.time != time:  # no ranger measured in this step
            self.measured[k] = False
        elif beams.due is None:  # every ranger measured, the beams are the row
            self.measured[k] = True
            self.ranges[k], self.intensities[k] = beams.ranges, beams.intensities
        else:
            self.measured[k] = beams.due
            taken = int(np.count_nonzero(beams.ray_due))
            self.ranges[k, :taken], self.intensities[k, :taken] = beams.ranges[beams.ray_due], \
                beams.intensities[beams.ray_due]

    def rows(self, count: int) -> ScanRows:
        return ScanRows(self.first, self.lengths, self.ranges[:count], self.intensities[:count],
                        self.measured[:count])


def _copy_rows(arrays: Sequence[np.ndarray], rows: np.ndarray) -> None:
    """Copy ``arrays``, one per row of ``rows`` and each of its dtype and row shape, into ``rows``: their bytes end
    to end, joined by one C call (np.concatenate checked and converted each small array: two to four times as long).
    An array of another size fails (the byte counts differ); the simulation's arrays keep their dtypes."""
    memoryview(rows).cast("B")[:] = b"".join(arrays)


def _column(value: Any, sim: Simulation) -> _Column:
    """The column for a quantity's values, shaped after one step's ``value``."""
    if isinstance(value, fields.LatestScans):
        counts = [len(robot.rangers) for robot in sim.robots]
        first = tuple(int(i) for i in np.concatenate([[0], np.cumsum(counts)]))
        return _Scans.empty(first, tuple(r.sensor.samples for robot in sim.robots for r in robot.rangers))
    return _Array.like(value)


def _step_values(topic: Topic) -> StepValues:
    """What ``topic``'s values are made of: it must be a per-step topic."""
    if not isinstance(topic.values, StepValues):
        raise TypeError(f"{topic.name} is not published every step")
    return topic.values


@dataclass(frozen=True)
class BatchLayout:
    """Where a batch's columns are in its one buffer: fixed when a recording makes its first batch, the same for
    all its batches, and sent to the writer once. The writer's batches are views of the same slots laid out the
    same way: nothing to pickle or rebuild per batch."""

    size: int
    """Steps (rows) a batch has room for."""
    columns: tuple[_Column, ...]
    """Each quantity's column without rows: its arrays' dtypes and row shapes."""
    offsets: tuple[tuple[int, ...], ...]
    """Per column, where each of its arrays starts in the buffer (bytes, multiples of 8: any dtype's alignment)."""
    nbytes: int
    uses: tuple[tuple[Topic, tuple[int, ...]], ...]
    """Per topic, the columns of the quantities its values are derived from."""

    @classmethod
    def of(cls, columns: Sequence[_Column], uses: Sequence[tuple[Topic, tuple[int, ...]]], size: int) -> BatchLayout:
        """The columns' arrays end to end, each at a multiple of 8 bytes."""
        at, offsets = 0, []
        for column in columns:
            starts = []
            for array in column.arrays():
                starts.append(at)
                at += -(-size * math.prod(array.shape[1:]) * array.itemsize // 8) * 8
            offsets.append(tuple(starts))
        return cls(size, tuple(columns), tuple(offsets), at, tuple(uses))


class StepBatch:
    """Up to ``layout.size`` consecutive steps' quantities (:class:`~stage_sim.interface.topics.Quantity`), a
    column per quantity the topics read: one the topics share (odom's and /tf's odometry poses, /clock's sim
    time, which also times the steps) is kept once a step, and each topic's values are derived for all the
    steps at once where they are read (:meth:`values`, in the writer process)."""

    def __init__(self, layout: BatchLayout, quantities: tuple[Quantity, ...] = (),
                 buffer: np.ndarray | None = None) -> None:
        """``quantities``: what :meth:`capture` keeps for each column; none for the writer's batches, which only
        read. ``buffer``: the bytes the columns are views of (a shared slot), ``layout.nbytes`` of them; by
        default the batch's own."""
        self.layout = layout
        self._quantities = quantities
        names = [quantity.kept for quantity in quantities]
        self._keep = attrgetter(*names) if names else None
        self._several = len(names) > 1
        self._kept: list[Any] = []
        """What :meth:`capture` kept of the steps not yet in the columns: a tuple per step (one value per
        quantity), or the one value when there is one quantity."""
        self.buffer = np.empty(layout.nbytes, np.uint8) if buffer is None else buffer
        """Everything the batch holds: every column's arrays."""
        self._columns = [
            column.on([np.ndarray((layout.size, *array.shape[1:]), array.dtype, self.buffer, offset)
                       for array, offset in zip(column.arrays(), offsets, strict=True)])
            for column, offsets in zip(layout.columns, layout.offsets, strict=True)]
        self.count = 0

    @classmethod
    def first(cls, sim: Simulation, stepped: Sequence[Topic], size: int) -> StepBatch:
        """An empty batch for the values of the ``stepped`` topics, shaped after the simulation's."""
        quantities = [SIM_TIME_US]  # the steps' times, whatever the topics
        for topic in stepped:
            quantities += [q for q in _step_values(topic).reads if q not in quantities]
        uses = [(topic, tuple(quantities.index(q) for q in _step_values(topic).reads)) for topic in stepped]
        columns = [_column(quantity.read(sim), sim) for quantity in quantities]
        return cls(BatchLayout.of(columns, uses, size), tuple(quantities))

    def over(self, buffer: np.ndarray) -> StepBatch:
        """An empty batch like this one, whose columns are views of ``buffer`` (a slot the writer shares)."""
        return StepBatch(self.layout, self._quantities, buffer)

    def take_steps(self, other: StepBatch) -> None:
        """Hold the steps ``other`` holds, which is left empty: the steps kept by reference move, not their values,
        so ``other`` must not be settled (the stepping side keeps steps in a batch of its own, then moves them
        into the slot it hands over)."""
        if other.count != len(other._kept):
            raise ValueError("the batch's steps are already copied into its own buffer")
        self._kept, other._kept = other._kept, []
        self.count, other.count = other.count, 0

    def clear(self) -> None:
        """Empty this batch to fill it again (its buffer is kept)."""
        self.count = 0
        self._kept.clear()

    def capture(self, sim: Simulation) -> bool:
        """Keep the step just taken: the quantities of the topics the batch was made for. Whether the batch is
        now full."""
        self._kept.append(self._keep(sim))
        self.count += 1
        return self.count == self.layout.size

    def settle(self) -> None:
        """Copy the steps kept into the columns, each quantity's in one call (what the batch sends, the values it
        derives, are then the kept steps' too)."""
        if not self._kept:
            return
        kept, start = self._kept, self.count - len(self._kept)
        by_quantity = list(zip(*kept, strict=True)) if self._several else [kept]
        seconds = [time_us / fields.MICROSECONDS for time_us in by_quantity[0]]  # the sim time as the simulation has it
        for column, values in zip(self._columns, by_quantity, strict=True):
            column.pack(values, seconds, start)
        self._kept = []

    @property
    def times(self) -> np.ndarray:
        """The sim time (µs) of each step held, in order."""
        self.settle()
        return self._columns[0].rows(self.count)

    def values(self) -> list[Any]:
        """Each topic's values for all the steps held (a leading axis per step), in the topics' order."""
        self.settle()
        rows = [column.rows(self.count) for column in self._columns]
        return [_step_values(topic).derive(*[rows[i] for i in columns]) for topic, columns in self.layout.uses]
