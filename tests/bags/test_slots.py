"""The slots a recording's batches travel in: shared with a second mapping (the writer's), reused most recently
freed first (a recording's memory follows its batches in flight), and a writer gone is seen, not waited for."""

from __future__ import annotations

import os

import numpy as np

from stage_sim.bags.slots import FreeSlots, SharedSlots, free


def test_what_one_side_writes_in_a_slot_the_other_side_reads() -> None:
    ours, fd = SharedSlots.create(3, 4096)
    try:
        theirs = SharedSlots(fd, 3, 4096)
    finally:
        os.close(fd)
    ours.buffers[1][:] = np.arange(4096) % 251
    np.testing.assert_array_equal(theirs.buffers[1], np.arange(4096) % 251)
    assert not theirs.buffers[0].any() and not theirs.buffers[2].any()


def test_the_slot_freed_last_is_filled_first_and_a_writer_gone_frees_nothing() -> None:
    freed, freeing = os.pipe()
    slots = FreeSlots(4, freed)
    taken = [slots.take(wait=False) for _ in range(4)]
    assert taken == [0, 1, 2, 3] and slots.take(wait=False) is None  # all in flight: a real-time batch drops
    for slot in (2, 0):
        free(freeing, slot)
    assert slots.take(wait=True) == 0  # the one freed last, whose pages are warm
    assert slots.take(wait=True) == 2
    os.close(freeing)  # the writer has gone
    assert slots.take(wait=True) is None and slots.writer_gone
    slots.close()

