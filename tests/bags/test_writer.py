"""The writer process's body, fed by hand: a simulator killed in the middle of sending a batch (its frame or
its arrays) still leaves a complete bag of every whole batch it sent."""

from __future__ import annotations

import os
import struct
import threading
from multiprocessing.connection import Connection

import pytest

from stage_sim.bags.messages import MessageBuilder
from stage_sim.bags.step_state import StepBatch
from stage_sim.bags.topics import stageros_topics
from stage_sim.bags.writer import BatchFrame, Closed, Opened, WriterPlan, send_batch, write_bag
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world
from tests.bags.readers import READERS
from tests.bags.test_recorder import names_of
from tests.bags.worlds import two_robot_world


@pytest.mark.parametrize("cut", ["in its frame", "in its arrays"])
def test_a_batch_cut_short_ends_the_input_and_the_bag_is_still_finished(tmp_path, cut) -> None:
    sim = Simulation(load_world(two_robot_world(tmp_path)), seed=1)
    names = names_of(sim)
    topics = stageros_topics(names, False)
    builder = MessageBuilder(sim, names, topics)
    path = tmp_path / "cut.mcap"
    steps_in, steps_out = os.pipe()
    reports_in, reports_out = os.pipe()
    steps, reports = Connection(steps_out, readable=False), Connection(reports_in, writable=False)
    writer = threading.Thread(target=write_bag, args=(
        WriterPlan(path, topics, 0.0, list(builder.static(sim)), builder.stepping),
        Connection(steps_in, writable=False), Connection(reports_out, readable=False)))
    writer.start()
    assert reports.recv() == Opened(None)
    batch = StepBatch.first(sim, names, builder.stepping.stepped, 5)
    for _ in range(5):
        sim.step()
        batch.capture(sim)
    send_batch(steps, batch)
    if cut == "in its arrays":
        steps.send(BatchFrame(b"the next batch, without its arrays", 3))
    os.write(steps.fileno(), struct.pack("!i", 1000) + b"\x80\x05 half a message")  # killed while sending it
    steps.close()
    writer.join(timeout=30)
    assert reports.recv() == Closed(1 + 5 * 12)
    bag = READERS["rosbags"](path)  # complete: rosbags refuses a file without its summary
    assert len(bag.messages["/clock"]) == 5
