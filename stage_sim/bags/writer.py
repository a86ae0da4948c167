"""The bag's writer process: turns the steps a simulation sends it into messages in the MCAP file.

Why a process and not a thread: refilling and writing a 100-robot step (400 messages) costs about as much CPU
as simulating it, and a thread shares the simulation's GIL (recording then cost half the simulation rate). In a
process of its own it runs on another core, and the stepping side only copies each step
(:class:`~stage_sim.bags.step_state.StepBatch`) and sends batches of steps through a pipe.

The process runs :func:`main` with ``STEPS REPORTS`` (:data:`stage_sim.bags.recorder.WRITER_MAIN`): a fresh
interpreter, not a fork of a process that may run threads, and not multiprocessing's spawn, which would re-run
the user's main script. STEPS and REPORTS are its two pipes' file descriptors, framed by
:mod:`multiprocessing.connection`: reports and the plan are pickled, a batch of steps is sent as its buffer
alone (:func:`send_batch`), laid out as the plan said (:class:`~stage_sim.bags.step_state.BatchLayout`). It first
reads a :class:`WriterPlan` from the steps pipe and answers on the reports pipe with :class:`Opened` once the
file is created and the latched messages are on disk, :class:`Failed` when the disk refuses a write (it then
reads and discards what comes, so the simulation is never blocked by a dead recording), and :class:`Closed` at
the end. It reads batches of steps until :class:`Finish`, or until the pipe ends without one (the simulation was
killed): it then still writes the summary, so a kill -9 of the simulator leaves a complete bag of every step
it had sent. It ignores SIGINT and SIGTERM: Ctrl-C in a terminal reaches the whole process group, and the
simulation's own handler closes the recording in order.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import traceback
from collections.abc import Sequence
from dataclasses import dataclass, field
from multiprocessing.connection import Connection
from pathlib import Path

from stage_sim.bags.container import McapBag
from stage_sim.bags.errors import BagError
from stage_sim.bags.step_messages import StepMessages
from stage_sim.bags.step_state import HEAD, BatchLayout, StepBatch
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
    """How every batch sent is laid out: the writer receives each into a batch of this layout."""


def send_batch(steps: Connection, batch: StepBatch) -> None:
    """Send ``batch`` as one message, its buffer: the pipe's write takes it from the batch's memory and drops
    the interpreter lock meanwhile (raises OSError when the writer is gone)."""
    steps.send_bytes(batch.packed())


def send_finish(steps: Connection, finish: Finish) -> None:
    """End the batches (a head of no steps, which no batch sent has) and send ``finish``."""
    steps.send_bytes(bytes(HEAD.itemsize))
    steps.send(finish)


def receive_batch(steps: Connection, batch: StepBatch) -> Finish | None:
    """Receive the next batch into ``batch``, whose columns are views of its buffer: nothing to unpickle or
    rebuild. At the end of the batches, the :class:`Finish` that follows. Raises EOFError or OSError when the
    sender ended first, maybe in the middle of a batch (Connection reads a whole message before it copies it
    into the buffer: a batch cut short leaves nothing of itself)."""
    size = steps.recv_bytes_into(batch.buffer)
    batch.unpack()
    if not batch.count:
        return steps.recv()
    if size != batch.buffer.nbytes:  # a bug: the sender's batches are laid out otherwise
        raise ValueError(f"a batch of {size} bytes came, one of {batch.buffer.nbytes} was expected")
    return None


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
    """The process: ``STEPS REPORTS`` are the file descriptors of its two pipes."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    steps, reports = Connection(int(argv[0]), writable=False), Connection(int(argv[1]), readable=False)
    try:
        plan = steps.recv()
    except (EOFError, OSError):  # the simulation ended before it sent the plan
        return
    write_bag(plan, steps, reports)
    # The bag is closed and reported: end without the interpreter's teardown (of numpy, foxglove, ...), which
    # took 50-80 ms that the simulation's close() waited for, as long as recording 6,000 steps of one robot.
    sys.stderr.flush()
    os._exit(0)


def _report(reports: Connection, report: Opened | Failed | Closed) -> None:
    """Tell the simulation, if it is still there to hear (after a kill -9 the bag is finished all the same)."""
    with contextlib.suppress(BrokenPipeError):
        reports.send(report)


def write_bag(plan: WriterPlan, steps: Connection, reports: Connection) -> None:
    """Open the bag, write the latched messages, then every step sent, then the summary."""
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
        metadata = _write_steps(writer, steps, StepBatch(plan.batches))
        if writer.error is None:
            try:
                bag.finish(metadata)
            except OSError as exc:
                _report(reports, Failed(exc.strerror or str(exc)))
        _report(reports, Closed(writer.count))
    except BaseException:  # a bug: the stepping side raises it with this traceback
        bag.abort()
        _report(reports, Closed(writer.count, traceback.format_exc()))


def _write_steps(writer: _Writer, steps: Connection, batch: StepBatch) -> dict[str, str]:
    """Write what comes, received into ``batch`` each time, until :class:`Finish` (its metadata) or the end of the
    pipe (the sender was killed)."""
    while True:
        try:
            finish = receive_batch(steps, batch)
        except (EOFError, OSError):  # OSError: the sender was killed in the middle of a batch
            stopped = "its start" if writer.last_us is None else f"sim time {writer.last_us / 1e6:g} s"
            return {"interrupted": f"the simulation ended without closing the bag after {stopped}"}
        if finish is not None:
            return finish.metadata
        writer.steps(batch)
