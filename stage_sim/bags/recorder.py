"""Record a running simulation into an MCAP bag without holding up its steps.

After every step the stepping thread copies what the step published (:class:`StepState`) into a bounded
queue and goes on; a writer thread builds, serialises and writes the messages. When the queue is full (the
writer, which shares the CPU with the simulation, or the disk cannot keep up):

* a lossless recording (every run that is not paced to the wall clock: lockstep, ``--speedup 0``) waits
  for the writer: the simulation slows down and every step is recorded;
* a real-time recording drops the step rather than fall behind the wall clock: it is counted, the count is
  said at exit (whose status is then non-zero) and stored in the bag's ``stage_sim`` metadata record.

A write error (full disk, file size limit) stops the recording with one message on stderr; the simulation
goes on and the file stays readable up to its last chunk.
"""

from __future__ import annotations

import queue
import sys
import threading
from dataclasses import dataclass
from pathlib import Path

from stage_sim.bags.container import McapBag
from stage_sim.bags.errors import BagError
from stage_sim.bags.messages import TYPESTORE, MessageBuilder, StepState
from stage_sim.bags.topics import select, stageros_topics
from stage_sim.interface.names import RobotNames
from stage_sim.sim.simulation import Simulation

BATCH_STEPS = 64
"""The writer thread is woken once per this many queued steps (at most half the queue; or every WAKE_S): each
wake-up costs the stepping thread a hand-over of the GIL, so waking per step would cost more than the writing."""
WAKE_S = 0.1
QUEUE_BYTES = 64 * 1024 * 1024
"""Memory the queue of pending steps may hold (ranges and intensities dominate: 8 bytes per beam)."""


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
        """Open the bag and write the latched messages (/tf_static, and /map when ``with_map``).

        ``speedup``: the run's; ``<= 0`` (not paced) makes the recording lossless: :meth:`record_step` waits for
        room in the queue instead of dropping the step.
        ``topics`` restricts the recording to those names (relative ones resolved in ``namespace``).
        Raises ValueError for an unknown topic and BagError when the file cannot be written."""
        self._sim = sim
        self._prog = prog
        self.lossless = speedup <= 0
        self._names = names
        self.topics = select(stageros_topics(names, with_map, namespace), topics, namespace)
        self._builder = MessageBuilder(sim, names, self.topics)
        self._bag = McapBag(Path(path), self.topics, TYPESTORE, speedup)
        self.messages = self.dropped_steps = self.dropped_messages = 0
        self.error: str | None = None
        self.summary: BagSummary | None = None
        """What was recorded, once :meth:`close` has run."""
        self._crash: BaseException | None = None
        try:
            for topic, log_time, data in self._builder.static(sim):
                self._bag.write(topic, log_time, data)
                self.messages += 1
            self._bag.flush()  # the latched messages are on disk before the first step: a kill -9 keeps them
        except OSError as exc:
            self._bag.abort()
            raise BagError(f"cannot write bag {path}: {exc.strerror or exc}") from None
        beams = sum(r.sensor.samples for robot in sim.robots for r in robot.rangers)
        self._queue: queue.Queue[StepState | None] = queue.Queue(
            maxsize=max(16, min(10_000, QUEUE_BYTES // (8 * beams + 64 * len(sim.robots) + 64))))
        self._batch = min(BATCH_STEPS, self._queue.maxsize // 2)
        self._wake = threading.Event()
        self._thread = threading.Thread(target=self._drain, name="bag-writer", daemon=True)
        self._thread.start()

    @property
    def failed(self) -> bool:
        """Whether writing has stopped on an error (the simulation may go on; nothing more is recorded)."""
        return self.error is not None

    def record_step(self) -> None:
        """Queue what the step just taken published: a full queue makes a lossless recording wait for the
        writer and a real-time one drop the step."""
        if self.failed:
            return
        state = StepState.capture(self._sim, self._names, self._builder.stepped)
        try:
            self._queue.put_nowait(state)
        except queue.Full:
            if not (self.lossless and self._wait_for_room(state)):
                self.dropped_steps += 1
                self.dropped_messages += self._builder.publications(state)
                return
        if self._queue.qsize() >= self._batch:
            self._wake.set()

    def _wait_for_room(self, state: StepState) -> bool:
        """Queue ``state`` once the writer has made room; False if the writer stopped meanwhile (an error)."""
        self._wake.set()
        while self._thread.is_alive() and not self.failed and self._crash is None:
            try:
                self._queue.put(state, timeout=WAKE_S)
                return True
            except queue.Full:
                self._wake.set()
        return False

    def close(self) -> BagSummary:
        """Write what is queued, then the index: the file is complete. Safe to call once, also after errors."""
        self._queue.put(None)
        self._wake.set()
        self._thread.join()
        if self._crash is not None:
            self._bag.abort()
            raise self._crash
        if self.error is None:
            try:
                self._bag.finish({"dropped_steps": str(self.dropped_steps),
                                  "dropped_messages": str(self.dropped_messages)})
            except OSError as exc:
                self.error = exc.strerror or str(exc)
        self.summary = BagSummary(self._bag.path, self.messages, self.dropped_steps, self.dropped_messages, self.error)
        return self.summary

    def _drain(self) -> None:
        """The writer thread: build and write queued steps, a batch per wake-up, until the closing None."""
        while True:
            self._wake.wait(WAKE_S)
            self._wake.clear()
            while True:
                try:
                    state = self._queue.get_nowait()
                except queue.Empty:
                    break
                if state is None:
                    return
                self._write(state)

    def _write(self, state: StepState) -> None:
        """One step's messages into the bag; a write error stops the recording, a bug is kept for close()."""
        if self.error is None and self._crash is None:
            try:
                for topic, log_time, data in self._builder.step(state):
                    self._bag.write(topic, log_time, data)
                    self.messages += 1
            except OSError as exc:
                self.error = f"{exc.strerror or exc} at sim time {state.sim_time_us / 1e6:g} s"
                self._bag.abort()
                print(f"{self._prog}: cannot write bag {self._bag.path}: {self.error}; recording stopped (recover "
                      f"what was written with: stage_sim recover {self._bag.path})", file=sys.stderr, flush=True)
            except BaseException as exc:  # a bug: re-raised by close() on the caller's thread
                self._crash = exc
