"""What steps published, copied off the simulation: what the stepping side sends the bag writer process.

The stepping side copies each step into a :class:`StepBatch`, column by column (one preallocated array per
quantity the per-step topics read, :class:`~stage_sim.interface.topics.Quantity`, a row per step), and sends the
batch whole: a step costs it a few array copies, and pickling a batch a few arrays however many steps it holds
(a step's values pickled one by one cost about as much as simulating a one-robot step). The writer derives each
topic's values for all the batch's steps at once (:meth:`StepBatch.values`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from stage_sim.interface import fields
from stage_sim.interface.names import RobotNames
from stage_sim.interface.topics import SIM_TIME_US, Quantity, StepValues, Topic

if TYPE_CHECKING:
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
    """One value of a per-step topic, for the steps of a batch: a row per step."""

    @abstractmethod
    def empty(self, size: int) -> _Column:
        """A column like this one with room for ``size`` steps."""

    @abstractmethod
    def put(self, k: int, value: Any) -> None:
        """Copy step ``k``'s value."""

    @abstractmethod
    def rows(self, count: int) -> Any:
        """The first ``count`` steps' values at once, a leading axis per step: what a topic's layout reads."""

    @abstractmethod
    def head(self, count: int) -> _Column:
        """The first ``count`` rows (views): what is pickled of a batch that is not full."""


class _Array(_Column):
    """An array value (poses, velocities, stall flags) or a number (the sim time)."""

    def __init__(self, data: np.ndarray) -> None:
        self.data = data

    @classmethod
    def like(cls, value: Any) -> _Array:
        """An empty column for values like ``value``."""
        value = np.asarray(value)
        return cls(np.empty((0, *value.shape), value.dtype))

    def empty(self, size: int) -> _Array:
        return _Array(np.empty((size, *self.data.shape[1:]), self.data.dtype))

    def put(self, k: int, value: Any) -> None:
        self.data[k] = value

    def rows(self, count: int) -> np.ndarray:
        return self.data[:count]

    def head(self, count: int) -> _Array:
        return _Array(self.data[:count])


class _Scans(_Column):
    """The scans a step measured (:class:`fields.LatestScans`), packed: the measured rangers' beams end to end in
    one row, and which rangers measured."""

    def __init__(self, first: tuple[int, ...], lengths: tuple[int, ...], size: int) -> None:
        self.first, self.lengths = first, lengths
        self.beams = sum(lengths)
        self.ranges = np.empty((size, self.beams), np.float32)
        self.intensities = np.empty((size, self.beams), np.float32)
        self.measured = np.zeros((size, len(lengths)), bool)

    def empty(self, size: int) -> _Scans:
        return _Scans(self.first, self.lengths, size)

    def put(self, k: int, value: fields.LatestScans) -> None:
        beams = value.beams
        if beams is None or beams.time != value.time:  # no ranger measured in this step
            self.measured[k] = False
        elif beams.due is None:  # the common case: every ranger measured, the beams are the row
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

    def head(self, count: int) -> _Scans:
        head = _Scans(self.first, self.lengths, 0)
        head.ranges, head.intensities, head.measured = (
            self.ranges[:count], self.intensities[:count], self.measured[:count])
        return head


def _column(value: Any, sim: Simulation) -> _Column:
    """The column for a quantity's values, shaped after one step's ``value``."""
    if isinstance(value, fields.LatestScans):
        counts = [len(robot.rangers) for robot in sim.robots]
        first = tuple(int(i) for i in np.concatenate([[0], np.cumsum(counts)]))
        return _Scans(first, tuple(r.sensor.samples for robot in sim.robots for r in robot.rangers), 0)
    return _Array.like(value)


def _step_values(topic: Topic) -> StepValues:
    """What ``topic``'s values are made of: it must be a per-step topic."""
    if not isinstance(topic.values, StepValues):
        raise TypeError(f"{topic.name} is not published every step")
    return topic.values


class StepBatch:
    """Up to ``size`` consecutive steps' quantities (:class:`~stage_sim.interface.topics.Quantity`), a column per
    quantity the topics read: one the topics share (odom's and /tf's odometry poses, /clock's sim time, which
    also times the steps) is copied once a step, and each topic's values are derived for all the steps at once
    where they are read (:meth:`values`, in the writer process)."""

    def __init__(self, quantities: tuple[Quantity, ...], columns: list[_Column],
                 uses: list[tuple[Topic, tuple[int, ...]]], size: int) -> None:
        self._quantities = quantities
        self._columns = [column.empty(size) for column in columns]
        self._uses = uses
        """Per topic, the columns of the quantities its values are derived from."""
        self.count = 0
        pairs = list(zip((quantity.read for quantity in quantities), self._columns, strict=True))
        self._arrays = [(read, column.data) for read, column in pairs if isinstance(column, _Array)]
        """What :meth:`capture` copies by a row assignment (inlined: a method call per quantity costs as much)."""
        self._packed = [(read, column) for read, column in pairs if not isinstance(column, _Array)]

    @classmethod
    def first(cls, sim: Simulation, names: Sequence[RobotNames], stepped: Sequence[Topic], size: int) -> StepBatch:
        """An empty batch for the values of the ``stepped`` topics, shaped after the simulation's."""
        quantities = [SIM_TIME_US]  # the steps' times, whatever the topics
        for topic in stepped:
            quantities += [q for q in _step_values(topic).reads if q not in quantities]
        uses = [(topic, tuple(quantities.index(q) for q in _step_values(topic).reads)) for topic in stepped]
        columns = [_column(quantity.read(sim), sim) for quantity in quantities]
        return cls(tuple(quantities), columns, uses, size)

    def empty(self, size: int) -> StepBatch:
        """An empty batch like this one (the stepping side starts one as it hands the last over)."""
        return StepBatch(self._quantities, self._columns, self._uses, size)

    def clear(self) -> None:
        """Empty this batch to fill it again (its arrays are kept: the sender has sent their contents)."""
        self.count = 0

    @property
    def full(self) -> bool:
        return self.count == len(self._columns[0].data)

    def capture(self, sim: Simulation) -> None:
        """Copy the step just taken: the quantities of the topics the batch was made for."""
        k = self.count
        for read, data in self._arrays:
            data[k] = read(sim)
        for read, column in self._packed:
            column.put(k, read(sim))
        self.count += 1

    @property
    def times(self) -> np.ndarray:
        """The sim time (µs) of each step held, in order."""
        return self._columns[0].rows(self.count)

    def values(self) -> list[Any]:
        """Each topic's values for all the steps held (a leading axis per step), in the topics' order."""
        rows = [column.rows(self.count) for column in self._columns]
        return [_step_values(topic).derive(*[rows[i] for i in columns]) for topic, columns in self._uses]

    def __getstate__(self) -> dict[str, Any]:
        """Only the rows filled travel to the writer, which reads them but copies no step (the quantities'
        readers, functions, stay behind)."""
        return {"count": self.count, "_quantities": (), "_arrays": [], "_packed": [], "_uses": self._uses,
                "_columns": [column.head(self.count) for column in self._columns]}
