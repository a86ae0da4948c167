"""The memory a recording's batches of steps travel in: slots shared by the stepping side and the writer process.

The stepping side copies each batch's steps straight into a free slot (:class:`~stage_sim.bags.step_state.
StepBatch` columns are views of it) and pipes the writer only the slot's number and step count; the writer reads
the steps where they are and, once their messages are written, pipes the slot's number back (:class:`FreeSlots`).
When whole batches travelled through a pipe, each byte was copied twice more, by a system call on each side:
a resting robot's recording cost its stepping thread about 1 µs a step more, of a step of about 11 µs.

The slots are one mapping of an anonymous file (``memfd_create``; elsewhere an unlinked temporary file) whose
descriptor the writer process inherits: nothing is left behind by a kill -9 of either side, and a slot the
writer was told of stays readable to it after the simulation is gone. Its pages take memory only once written:
free slots are reused most recently freed first, so a recording uses as many as it has batches in flight.
"""

from __future__ import annotations

import mmap
import os
import tempfile
from select import select

import numpy as np

SLOT_NUMBER = np.dtype("<i4")
"""How a slot's number travels back to the stepping side."""


class SharedSlots:
    """``count`` buffers of ``size`` bytes in one mapping of a file that another process can map too."""

    def __init__(self, fd: int, count: int, size: int) -> None:
        """Map the slots of the file ``fd`` (the writer's side: inherited). The mapping outlives ``fd``, which the
        caller closes."""
        memory = np.frombuffer(mmap.mmap(fd, max(1, count * size)), np.uint8)
        self.buffers = [memory[k * size:(k + 1) * size] for k in range(count)]
        """Each slot's bytes."""

    @classmethod
    def create(cls, count: int, size: int) -> tuple[SharedSlots, int]:
        """New slots, of zero pages until written, and their file's descriptor, for the writer process."""
        if hasattr(os, "memfd_create"):
            fd = os.memfd_create("stage_sim-bag-steps")
        else:  # not Linux: a file with no name, in memory as long as it is mapped
            with tempfile.TemporaryFile() as file:
                fd = os.dup(file.fileno())
        os.ftruncate(fd, max(1, count * size))
        return cls(fd, count, size), fd


class FreeSlots:
    """The stepping side's account of the slots: which are free, taken from the writer's pipe of freed ones."""

    def __init__(self, count: int, freed: int) -> None:
        """``freed``: the reading end of the pipe the writer sends freed slots' numbers on."""
        self._free = list(range(count - 1, -1, -1))
        """Free slots, the next to use last: the one freed last, whose pages are mapped and warm."""
        self._freed = freed
        os.set_blocking(freed, False)
        self.writer_gone = False
        """Whether the pipe ended: the writer has exited, and frees nothing more."""

    def take(self, wait: bool) -> int | None:
        """A free slot (now taken), waiting for the writer to free one if ``wait``; None when there is none (the
        writer has gone, or it is busy and ``wait`` is false)."""
        self._collect()
        while wait and not self._free and not self.writer_gone:
            select([self._freed], [], [])
            self._collect()
        return self._free.pop() if self._free else None

    def _collect(self) -> None:
        """Add the slots the writer has freed since last time, without waiting."""
        try:
            data = os.read(self._freed, 65536)
        except BlockingIOError:
            return
        if not data:
            self.writer_gone = True
            return
        # Whole numbers only: each is written at once (4 bytes, under PIPE_BUF), and at most the recorder's
        # MAX_SLOTS are in the pipe (8 kB), which one read takes.
        self._free.extend(np.frombuffer(data, SLOT_NUMBER).tolist())

    def close(self) -> None:
        os.close(self._freed)


def free(freed: int, slot: int) -> None:
    """The writer's side: tell the stepping side that ``slot`` may be filled again (a write to a pipe of at least
    4 kB: whole, never interleaved, and never full while the stepping side reads it before it waits)."""
    os.write(freed, SLOT_NUMBER.type(slot).tobytes())
