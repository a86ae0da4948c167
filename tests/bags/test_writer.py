"""The writer process's body, fed by hand: a simulator killed in the middle of sending a batch (its note's
length or the note) still leaves a complete bag of every whole batch it sent, and nothing of the cut one; the
writer frees each slot once its steps are written."""

from __future__ import annotations

import os
import struct
import threading
from multiprocessing.connection import Connection

import pytest

from stage_sim.bags.messages import MessageBuilder
from stage_sim.bags.slots import FreeSlots, SharedSlots
from stage_sim.bags.step_state import StepBatch
from stage_sim.bags.topics import stageros_topics
from stage_sim.bags.writer import NOTE, Closed, Opened, WriterPlan, send_batch, write_bag
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world
from tests.bags.readers import READERS
from tests.bags.test_recorder import names_of
from tests.bags.worlds import two_robot_world


@pytest.mark.parametrize("cut", ["in its length", "in the note"])
def test_a_batch_cut_short_ends_the_input_and_the_bag_is_still_finished(tmp_path, cut) -> None:
    sim = Simulation(load_world(two_robot_world(tmp_path)), seed=1)
    names = names_of(sim)
    topics = stageros_topics(names, False)
    builder = MessageBuilder(sim, names, topics)
    path = tmp_path / "cut.mcap"
    steps_in, steps_out = os.pipe()
    reports_in, reports_out = os.pipe()
    freed_in, freed_out = os.pipe()
    steps, reports = Connection(steps_out, readable=False), Connection(reports_in, writable=False)
    pending = StepBatch.first(sim, builder.stepping.stepped, 5)
    slots, fd = SharedSlots.create(1, pending.layout.nbytes)
    theirs = SharedSlots(fd, 1, pending.layout.nbytes)
    os.close(fd)
    batches = [pending.over(buffer) for buffer in slots.buffers]
    free = FreeSlots(1, freed_in)
    writer = threading.Thread(target=write_bag, args=(
        WriterPlan(path, topics, 0.0, list(builder.static(sim)), builder.stepping, pending.layout, 1),
        Connection(steps_in, writable=False), Connection(reports_out, readable=False), theirs, freed_out))
    writer.start()
    assert reports.recv() == Opened(None)
    times = []
    for steps_in_batch in (5, 2):  # a full batch, then a hand-over of fewer steps in the slot freed
        for _ in range(steps_in_batch):
            sim.step()
            pending.capture(sim)
            times.append(sim.sim_time_us)
        slot = free.take(wait=True)  # the one slot: the second batch's only once the writer has freed it
        assert slot == 0
        batches[slot].take_steps(pending)
        send_batch(steps, slot, batches[slot])
    # killed while sending the next one: within the length before the note, or the note's bytes
    os.write(steps.fileno(), struct.pack("!i", NOTE.size)[:2] if cut == "in its length" else
             struct.pack("!i", NOTE.size) + NOTE.pack(0, 3)[:5])
    steps.close()
    writer.join(timeout=30)
    assert reports.recv() == Closed(1 + 7 * 12)
    bag = READERS["rosbags"](path)  # complete: rosbags refuses a file without its summary
    assert [stamp for stamp, _ in bag.messages["/clock"]] == [time_us * 1000 for time_us in times]
