"""The bag's writer process: turns the steps a simulation sends it into messages in the MCAP file.

Why a process and not a thread: refilling and writing a 100-robot step (400 messages) costs about as much CPU
as simulating it, and a thread shares the simulation's GIL (recording then cost half the simulation rate). In a
process of its own it runs on another core, and the stepping side only copies each step
(:class:`~stage_sim.bags.step_state.StepBatch`) into memory both share (:mod:`stage_sim.bags.slots`).

The process runs :func:`main` with ``STEPS REPORTS SLOTS FREED`` (:data:`stage_sim.bags.recorder.WRITER_MAIN`):
a fresh interpreter, not a fork of a process that may run threads, and not multiprocessing's spawn, which would
re-run the user's main script. STEPS and REPORTS are two pipes' file descriptors, framed by
:mod:`multiprocessing.connection` (the plan and the reports are pickled); SLOTS is the shared slots' file, laid
out as the plan says (:class:`~stage_sim.bags.step_state.BatchLayout`); FREED a pipe on which the writer gives
back each slot once its steps are written. It first reads a :class:`WriterPlan` from the steps pipe and answers
on the reports pipe with :class:`Opened` once the file is created and the latched messages are on disk,
:class:`Failed` when the disk refuses a write (it then frees the slots it is told of unwritten, so the
simulation is never blocked by a dead recording), and :class:`Closed` at the end. Each batch sent is a note
of its slot and step count (:func:`send_batch`). It reads them until :class:`Finish`, or until the pipe ends
without one (the simulation was killed): it then still writes the summary, so a kill -9 of the simulator leaves
a complete bag of every step it had sent. It ignores SIGINT and SIGTERM: Ctrl-C in a terminal reaches the whole
process group, and the simulation's own handler closes the recording in order.
"""

from __future__ import annotations

import contextlib
import os
import signal
import struct
import sys
import traceback
from collections.abc import Sequence
from dataclasses import dataclass, field
from multiprocessing.connection import Connection
from pathlib import Path

from stage_sim.bags.container import McapBag
from stage_sim.bags.errors import BagError
from stage_sim.bags.slots import SharedSlots, free
from stage_sim.bags.step_messages import StepMessages
from stage_sim.bags.step_state import BatchLayout, StepBatch
from stage_sim.bags.topics import Topic


@dataclass(frozen=True)
class WriterPlan:
    """Everything the writer process needs, made by the stepping side from its simulation."""

    path: Path
    topics: list[Topic]
    speedup: float
    """The run's (``<= 0``: not paced; chunks then close by size only, see :mod:`stage_sim.bags.container`)."""
    static: list[tuple[str, int, bytes]]
    """The latched messages, serialised (/tf_static, /map)."""
    messages: StepMessages
    batches: BatchLayout
    """How every batch sent is laid out in its slot."""
    slots: int
    """How many slots of ``batches.nbytes`` the shared file holds."""


NOTE = struct.Struct("<qq")
"""What says a batch is sent: its slot, and how many steps it holds (none: the end of the batches)."""


def send_batch(steps: Connection, slot: int, batch: StepBatch) -> None:
    """Send ``batch``, a view of shared slot ``slot``: copy the steps it keeps into the slot, then tell the writer
    (raises OSError when the writer is gone). The slot is the writer's until it frees it."""
    batch.settle()
    steps.send_bytes(NOTE.pack(slot, batch.count))


def send_finish(steps: Connection, finish: Finish) -> None:
    """End the batches (a note of no steps, which no batch sent has) and send ``finish``."""
    steps.send_bytes(NOTE.pack(-1, 0))
    steps.send(finish)


def receive_batch(steps: Connection, batches: list[StepBatch]) -> int | Finish:
    """The slot of the next batch sent, whose batch in ``batches`` (one per slot, its columns views of it: nothing
    to unpickle or rebuild) now holds its steps; at the end of the batches, the :class:`Finish` that follows.
    Raises EOFError or OSError when the sender ended first, maybe in the middle of a note (Connection reads a
    whole message before it returns it: a note cut short leaves nothing of itself)."""
    slot, count = NOTE.unpack(steps.recv_bytes(NOTE.size))
    if not count:
        return steps.recv()
    batches[slot].count = count
    return slot


@dataclass(frozen=True)
class Finish:
    """The last thing sent: the run is over; ``metadata`` goes into the bag's ``stage_sim`` record."""

    metadata: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Opened:
    """The answer to the start: the file is there with the latched messages, or ``error`` says why not."""

    error: str | None


@dataclass(frozen=True)
class Failed:
    """A write was refused: the recording stopped at this point, the file is readable up to its last chunk."""

    error: str


@dataclass(frozen=True)
class Closed:
    """The end: how many messages are in the bag; ``crash``: the traceback of a bug in the writer."""

    messages: int
    crash: str | None = None


class _Writer:
    """The bag and its counts; a write error ends the writing, not the reading."""

    def __init__(self, bag: McapBag, messages: StepMessages, reports: Connection) -> None:
        self.bag = bag
        self._messages = messages
        self._reports = reports
        self.count = 0
        self.last_us: int | None = None
        """The sim time of the last step written."""
        self.error: str | None = None

    def write(self, log_times: Sequence[int], topics: Sequence[str], messages: Sequence[bytes | None]) -> None:
        self.bag.write(log_times, topics, messages)
        self.count += len(messages) - messages.count(None)

    def steps(self, batch: StepBatch) -> None:
        """Write the batch's steps, unless an earlier write failed (then they are dropped: the recording has
        stopped)."""
        if self.error is not None:
            return
        log_times, messages = self._messages.steps(batch)
        try:
            self.write(log_times, self._messages.names, messages)
        except OSError as exc:
            self.error = f"{exc.strerror or exc} at sim time {log_times[0] / 1e9:g} s"
            self.bag.abort()
            _report(self._reports, Failed(self.error))
            return
        self.last_us = log_times[-1] // 1000


def main(argv: list[str]) -> None:
    """The process: ``STEPS REPORTS SLOTS FREED`` are the file descriptors of its pipes and shared slots."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    steps, reports = Connection(int(argv[0]), writable=False), Connection(int(argv[1]), readable=False)
    try:
        plan = steps.recv()
    except (EOFError, OSError):  # the simulation ended before it sent the plan
        return
    slots = SharedSlots(int(argv[2]), plan.slots, plan.batches.nbytes)
    os.close(int(argv[2]))
    write_bag(plan, steps, reports, slots, int(argv[3]))
    # The bag is closed and reported: end without the interpreter's teardown (of numpy, foxglove, ...), which
    # took 50-80 ms that the simulation's close() waited for, as long as recording 6,000 steps of one robot.
    sys.stderr.flush()
    os._exit(0)


def _report(reports: Connection, report: Opened | Failed | Closed) -> None:
    """Tell the simulation, if it is still there to hear (after a kill -9 the bag is finished all the same)."""
    with contextlib.suppress(BrokenPipeError):
        reports.send(report)


def write_bag(plan: WriterPlan, steps: Connection, reports: Connection, slots: SharedSlots, freed: int) -> None:
    """Open the bag, write the latched messages, then every step sent (from ``slots``, each freed on ``freed``
    once written), then the summary."""
    try:
        bag = McapBag(plan.path, plan.topics, plan.speedup)
    except BagError as exc:
        _report(reports, Opened(str(exc)))
        return
    writer = _Writer(bag, plan.messages, reports)
    try:
        try:
            for topic, log_time, data in plan.static:
                writer.write((log_time,), (topic,), (data,))
            bag.flush()  # the latched messages are on disk before the first step: a kill -9 keeps them
        except OSError as exc:
            bag.abort()
            _report(reports, Opened(f"cannot write bag {plan.path}: {exc.strerror or exc}"))
            return
        _report(reports, Opened(None))
        batches = [StepBatch(plan.batches, buffer=buffer) for buffer in slots.buffers]
        metadata = _write_steps(writer, steps, batches, freed)
        if writer.error is None:
            try:
                bag.finish(metadata)
            except OSError as exc:
                _report(reports, Failed(exc.strerror or str(exc)))
        _report(reports, Closed(writer.count))
    except BaseException:  # a bug: the stepping side raises it with this traceback
        bag.abort()
        _report(reports, Closed(writer.count, traceback.format_exc()))


def _write_steps(writer: _Writer, steps: Connection, batches: list[StepBatch], freed: int) -> dict[str, str]:
    """Write the batches sent, each one of ``batches``, freeing its slot on ``freed`` once written, until
    :class:`Finish` (its metadata) or the end of the pipe (the sender was killed)."""
    while True:
        try:
            slot = receive_batch(steps, batches)
        except (EOFError, OSError):  # OSError: the sender was killed in the middle of a note
            stopped = "its start" if writer.last_us is None else f"sim time {writer.last_us / 1e6:g} s"
            return {"interrupted": f"the simulation ended without closing the bag after {stopped}"}
        if isinstance(slot, Finish):
            return slot.metadata
        writer.steps(batches[slot])
        with contextlib.suppress(BrokenPipeError):  # the simulation has gone: what it sent is still written
            free(freed, slot)
