"""Record a running simulation into an MCAP bag without holding up its steps.

After every step the stepping thread keeps what the step published in a :class:`StepBatch` (references) and goes
on; a batch of steps at a time is copied into a slot of memory shared with the bag's writer process
(:mod:`stage_sim.bags.slots`), which makes and writes the messages on another core and then frees the slot.
When the writer or the disk cannot keep up, no slot is free:

* a lossless recording (every run that is not paced to the wall clock: lockstep, ``--speedup 0``) waits
  for the writer to free one: the simulation slows down and every step is recorded;
* a real-time recording drops the batch rather than fall behind the wall clock: its steps are counted, the
  count is said at exit (whose status is then non-zero) and stored in the bag's ``stage_sim`` metadata record.
  It has slots for up to SLOTS_BYTES of batches, so it drops only when the writer falls that far behind.

A write error (full disk, file size limit) stops the recording with one message on stderr; the simulation
goes on and the file stays readable up to its last chunk.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from multiprocessing.connection import Connection
from pathlib import Path
from select import select as ready

from stage_sim.bags.errors import BagError
from stage_sim.bags.messages import MessageBuilder
from stage_sim.bags.slots import FreeSlots, SharedSlots
from stage_sim.bags.step_state import StepBatch
from stage_sim.bags.topics import select, stageros_topics
from stage_sim.bags.writer import Closed, Failed, Finish, Opened, WriterPlan, send_batch, send_finish
from stage_sim.interface.names import RobotNames
from stage_sim.sim.simulation import Simulation

BATCH_BYTES = 256 * 1024
"""Bytes of steps handed to the writer at once (at most BATCH_STEPS steps): one note to the writer and one
wake-up of it per batch instead of per step."""
BATCH_STEPS = 64
LOSSLESS_SLOTS = 4
"""Slots of a lossless recording: how many batches the simulation runs ahead of the writer before it waits.
Four, not one: with one, the simulation and the writer took turns (100 robots: each waited 2-4 ms a batch)."""
WAKE_S = 0.1
"""Wall seconds a step waits at most before its batch is handed over, however small: a slow (real-time)
recording reaches the writer, and the disk, within this."""
SLOTS_BYTES = 64 * 1024 * 1024
"""Memory the slots of a real-time recording may hold (ranges and intensities dominate: 8 bytes per beam); they
take memory only once used, and the freed ones are reused first."""
MAX_SLOTS = 2048
"""At most this many slots: the notes of as many batches in flight (20 bytes each) fit in the steps pipe (64 kB),
so a real-time recording never waits to send one, and their numbers freed and not yet read fit in the pipe
that carries them back."""
START_TIMEOUT_S = 120.0
"""How long the writer process may take to start and create the file (a cold start imports for seconds)."""


@dataclass(frozen=True)
class BagSummary:
    """What a recording wrote and lost, for the message at exit."""

    path: Path
    messages: int
    dropped_steps: int
    dropped_messages: int
    error: str | None

    @property
    def complete(self) -> bool:
        """Whether every step was recorded to the end: what the exit status of a recording run says."""
        return not (self.error or self.dropped_steps)

    def describe(self) -> str:
        """One line for the user."""
        text = f"bag {self.path}: {self.messages} messages"
        if self.dropped_steps:
            text += (f"; dropped {self.dropped_messages} messages of {self.dropped_steps} steps: at real time the "
                     "bag writer (which shares the CPU with the simulation) or the disk could not keep up; "
                     "a run with --speedup 0 records every step (see the 'stage_sim' metadata record)")
        if self.error:
            text += f"; recording stopped early: {self.error} (recover the rest with: stage_sim recover {self.path})"
        return text


class BagRecorder:
    """Records every step of ``sim`` (call :meth:`record_step` after each) until :meth:`close`."""

    def __init__(
        self, sim: Simulation, path: str | Path, names: list[RobotNames], *, namespace: str = "/",
        topics: list[str] | None = None, with_map: bool = False, prog: str = "stage_sim", speedup: float = 0.0,
    ) -> None:
        """Start the writer process, which creates the bag and writes the latched messages (/tf_static, and /map
        when ``with_map``) before this returns.

        ``speedup``: the run's; ``<= 0`` (not paced) makes the recording lossless: :meth:`record_step` waits for
        a free slot instead of dropping steps.
        ``topics`` restricts the recording to those names (relative ones resolved in ``namespace``).
        Raises ValueError for an unknown topic and BagError when the file cannot be written."""
        self._sim = sim
        self._prog = prog
        self.path = Path(path)
        self.lossless = speedup <= 0
        self._names = names
        self.topics = select(stageros_topics(names, with_map, namespace), topics, namespace)
        builder = MessageBuilder(sim, names, self.topics)
        self._messages = builder.stepping
        step_bytes = 8 * sum(r.sensor.samples for robot in sim.robots for r in robot.rangers) + 200 * len(sim.robots)
        batch_steps = max(1, min(BATCH_STEPS, BATCH_BYTES // step_bytes))
        self._pending = StepBatch.first(sim, self._messages.stepped, batch_steps)
        """The steps kept since the last hand-over, moved into a free slot's batch when handed over."""
        layout = self._pending.layout
        count = LOSSLESS_SLOTS if self.lossless else max(2, min(MAX_SLOTS, SLOTS_BYTES // layout.nbytes))
        try:
            slots, slots_fd = SharedSlots.create(count, layout.nbytes)
        except OSError as exc:  # no memory, or a file size limit below the slots' size
            raise BagError(f"cannot make the memory the steps go to the bag writer in: {exc.strerror or exc}") from None
        self._slots = [self._pending.over(buffer) for buffer in slots.buffers]
        plan = WriterPlan(self.path, self.topics, speedup, list(builder.static(sim)), builder.stepping, layout, count)
        try:
            self._process, self._steps, self._reports, freed = _start_writer(slots_fd)
        except OSError as exc:  # no processes left, or the interpreter is gone
            raise BagError(f"cannot start the bag writer process: {exc.strerror or exc}") from None
        finally:
            os.close(slots_fd)  # the mapping stays, and the writer has its own descriptor
        self._free = FreeSlots(count, freed)
        opened = None
        with contextlib.suppress(OSError):  # a writer that could not start: said below
            self._steps.send(plan)
            opened = self._next_report(START_TIMEOUT_S)
        if not isinstance(opened, Opened) or opened.error:
            self._steps.close()  # a writer still starting reads the end of its input and exits
            self._reports.close()
            self._free.close()
            reason = (opened.error if isinstance(opened, Opened)
                      else f"cannot write bag {self.path}: {self._writer_end()}")
            if self._process.poll() is None:
                self._process.kill()
                self._process.wait()
            raise BagError(reason)
        self.dropped_steps = self.dropped_messages = 0
        self.error: str | None = None
        self.summary: BagSummary | None = None
        """What was recorded, once :meth:`close` has run."""
        self._writer_lost = False
        """Whether the writer process went away (a batch could not be handed to it)."""
        self._closed: Closed | None = None
        """The writer's last report, once it has ended (early only after a bug)."""
        self._pending_since = 0.0

    @property
    def writer_pid(self) -> int:
        """The writer process's id (for a user, or a test, who wants to watch or pause it)."""
        return self._process.pid

    @property
    def failed(self) -> bool:
        """Whether writing has stopped on an error (the simulation may go on; nothing more is recorded). Cheap
        enough for every step: only flags, which the writer's reports set as a batch is handed over (a system call
        per step here cost as much as keeping the step)."""
        return self.error is not None or self._writer_lost or self._closed is not None

    def record_step(self) -> None:
        """Keep what the step just taken published; every batch's worth (or WAKE_S), hand it to the writer: a
        lossless recording waits for a free slot, a real-time one drops the batch when there is none."""
        if self.error is not None:
            return
        now = time.monotonic()
        if not self._pending.count:
            self._pending_since = now
        if self._pending.capture(self._sim) or now - self._pending_since >= WAKE_S:
            self._hand_over(wait=self.lossless)

    def _hand_over(self, wait: bool) -> None:
        """Copy the pending steps into a free slot and tell the writer; when none is free, wait for the writer to
        free one if ``wait``, else drop the steps."""
        pending = self._pending
        if self.failed:  # nothing more is recorded: close() says why
            pending.clear()
            return
        slot = self._free.take(wait)
        if slot is None:
            if self._free.writer_gone:
                self._writer_lost = True
            else:
                self.dropped_steps += pending.count
                self.dropped_messages += self._messages.publications(pending)
            pending.clear()
            return
        batch = self._slots[slot]
        batch.take_steps(pending)
        try:
            send_batch(self._steps, slot, batch)
        except OSError:
            self._writer_lost = True
        self._read_reports()

    def close(self) -> BagSummary:
        """Send what is pending, let the writer write the summary and wait for it: the file is complete. Safe
        to call once, also after errors; re-raises (as RuntimeError) a bug that crashed the writer."""
        if self._pending.count:
            self._hand_over(wait=True)  # nothing is paced any more: the last steps are never dropped
        if not self._writer_lost:
            try:
                send_finish(self._steps, Finish({"dropped_steps": str(self.dropped_steps),
                                                 "dropped_messages": str(self.dropped_messages)}))
            except OSError:
                self._writer_lost = True
        self._steps.close()
        while self._closed is None and (report := self._next_report(None)) is not None:
            self._take(report)
        self._reports.close()
        self._free.close()
        self._process.wait()
        messages = 0
        if self._closed is not None:
            messages = self._closed.messages
            if self._closed.crash:
                raise RuntimeError(f"the bag writer process failed:\n{self._closed.crash}")
        elif self.error is None:
            self.error = f"the bag writer process ended before the bag was complete ({self._writer_end()})"
        self.summary = BagSummary(self.path, messages, self.dropped_steps, self.dropped_messages, self.error)
        return self.summary

    def _next_report(self, timeout: float | None) -> Opened | Failed | Closed | None:
        """The writer's next report, None if it ended (or ``timeout`` passed) without one."""
        if self._reports.closed:
            return None
        if timeout is not None and not ready([self._reports], [], [], timeout)[0]:
            return None
        try:
            return self._reports.recv()
        except EOFError:
            return None

    def _read_reports(self) -> None:
        """Take the reports that have come, without waiting (once per batch handed over: hence select, not
        Connection.poll, which builds a selector per call)."""
        while not self._reports.closed and ready([self._reports], [], [], 0)[0]:
            try:
                self._take(self._reports.recv())
            except EOFError:  # the writer has ended: close() says how
                self._reports.close()

    def _take(self, report: Opened | Failed | Closed) -> None:
        """Note a report: a write error is said at once, the end is kept for close()."""
        if isinstance(report, Closed):
            self._closed = report
        elif isinstance(report, Failed) and self.error is None:
            self.error = report.error
            print(f"{self._prog}: cannot write bag {self.path}: {self.error}; recording stopped (recover what was "
                  f"written with: stage_sim recover {self.path})", file=sys.stderr, flush=True)

    def _writer_end(self) -> str:
        """How the writer process ended, for a message."""
        try:
            code = self._process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            return "the writer process does not answer"
        return f"the writer process exited with status {code}"


WRITER_MAIN = "import sys; sys.path[0] = sys.argv.pop(1); from stage_sim.bags.writer import main; main(sys.argv[1:])"
"""The writer process's program: :func:`stage_sim.bags.writer.main` of this very stage_sim (its folder replaces
the working directory at the head of the path, where another checkout of stage_sim may be: the writer would
then read this one's plan with other code)."""


def _start_writer(slots: int) -> tuple[subprocess.Popen, Connection, Connection, int]:
    """Start the writer process (:mod:`stage_sim.bags.writer`) on the shared ``slots``, with a pipe for steps, one
    for its reports and one for the slots it frees (whose reading end is returned); the writer holds the only
    reading end of the first, so a killed simulation ends its input."""
    steps_in, steps_out = os.pipe()
    reports_in, reports_out = os.pipe()
    freed_in, freed_out = os.pipe()
    root = str(Path(__file__).resolve().parents[2])  # where this stage_sim is, however the caller found it
    ends = (steps_in, reports_out, slots, freed_out)
    try:
        process = subprocess.Popen([sys.executable, "-c", WRITER_MAIN, root, *map(str, ends)],
                                   pass_fds=ends, stdin=subprocess.DEVNULL)
    except OSError:
        for fd in (steps_out, reports_in, freed_in):
            os.close(fd)
        raise
    finally:
        for fd in (steps_in, reports_out, freed_out):
            os.close(fd)
    return process, Connection(steps_out, readable=False), Connection(reports_in, writable=False), freed_in
