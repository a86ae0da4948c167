"""A batch of steps, sent as it travels to the bag writer (copied into a shared slot, which the writer maps on
its own, and noted through a pipe), gives back every step's values as the simulation had them: poses, times and
which rangers measured what (rangers at different rates, a robot without any)."""

from __future__ import annotations

import os
import pickle
from multiprocessing import Pipe

import numpy as np
import pytest

from stage_sim.bags.slots import SharedSlots
from stage_sim.bags.step_state import StepBatch
from stage_sim.bags.writer import receive_batch, send_batch
from stage_sim.interface import topics
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text
from tests.bags.worlds import REPO

WORLD = f"""
resolution 0.02
interval_sim 100
define floorplan model ( color "SlateGray" boundary 1 obstacle_return 1 )
floorplan( size [27.05 21.65 1.0] pose [13.525 10.825 0 0] bitmap "{REPO / 'maps/rooms.png'}" )
define fast ranger ( sensor( range [0.0 5.6] fov 240.0 samples 50 ) size [0.06 0.06 0.06] )
define slow ranger ( sensor( range [0.1 3.0] fov 90.0 samples 7 ) update_interval 300 size [0.06 0.06 0.06] )
define bot position ( size [0.4 0.3 0.2] drive "diff" odom_error [0.03 0.03 0 0.05] )
bot( pose [11.1 9.2 0 90] fast( pose [0.2 0 -0.1 0] ) slow( pose [-0.2 0 -0.1 180] ) )
bot( pose [4.0 4.0 0 0] )
bot( pose [6.0 4.0 0 0] slow( pose [0.2 0 -0.1 0] ) )
"""

STEPPED = [t for t in topics.PUBLISHED if t.timing is not topics.Timing.START]


class Trip:
    """The way from the stepping side to the writer: two slots, mapped once by each side, and the pipe of notes.
    The writer's batches are of the layout its plan brings (pickled)."""

    def __init__(self, batch: StepBatch) -> None:
        size = batch.layout.nbytes
        ours, fd = SharedSlots.create(2, size)
        try:
            theirs = SharedSlots(fd, 2, size)
        finally:
            os.close(fd)
        self.sending = [batch.over(buffer) for buffer in ours.buffers]
        layout = pickle.loads(pickle.dumps(batch.layout))
        self.received = [StepBatch(layout, buffer=buffer) for buffer in theirs.buffers]
        self.receiving, self.notes = Pipe(duplex=False)

    def travel(self, batch: StepBatch, slot: int = 0) -> StepBatch:
        """``batch``'s steps as the writer gets them through ``slot``; ``batch`` is left empty."""
        self.sending[slot].take_steps(batch)
        send_batch(self.notes, slot, self.sending[slot])
        assert receive_batch(self.receiving, self.received) == slot
        return self.received[slot]


def travelled(batch: StepBatch) -> StepBatch:
    """``batch`` as the writer gets it."""
    return Trip(batch).travel(batch)


@pytest.mark.parametrize("refilled", [False, True])
def test_a_sent_batch_gives_back_every_step(tmp_path, refilled) -> None:
    """Also a batch not full (a hand-over after WAKE_S) in a slot that held a full one: the slot still holds the
    earlier batch's steps past the rows filled, which the writer does not read."""
    sim = Simulation(load_world_text(WORLD, str(tmp_path / "w.world")), seed=2)
    for robot in range(3):
        sim.set_velocity(robot, 0.3, 0.0, 0.2 * robot)
    batch = StepBatch.first(sim, STEPPED, 10)
    trip = Trip(batch)
    if refilled:
        full = []
        for _ in range(10):
            sim.step()
            full.append(batch.capture(sim))
        assert full == [False] * 9 + [True]  # capture says when the batch is full
        assert trip.travel(batch, 1).count == 10
    expected = []
    for _ in range(7):  # not full
        sim.step()
        assert not batch.capture(sim)
        scans = {(r, k): (s.ranges.copy(), s.intensities.copy()) if s.stamp == sim.sim_time else None
                 for r, robot in enumerate(sim.scans) for k, s in enumerate(robot)}
        expected.append((sim.sim_time_us, sim.odometry_poses.copy(), sim.true_velocities.copy(), scans))
    received = trip.travel(batch, 1)
    assert received.count == 7
    values = dict(zip(STEPPED, received.values(), strict=True))
    np.testing.assert_array_equal(received.times, [time_us for time_us, *_ in expected])
    np.testing.assert_array_equal(values[topics.CLOCK], received.times)
    skipped = 0
    for k, (_, odometry, velocities, scans) in enumerate(expected):
        np.testing.assert_array_equal(values[topics.ODOM][0][k], odometry)
        np.testing.assert_array_equal(values[topics.GROUND_TRUTH][1][k], velocities)
        np.testing.assert_array_equal(values[topics.TF][k], odometry)
        step_scans = values[topics.SCAN].row(k)
        for (robot, ranger), scan in scans.items():
            packed = step_scans.measured(robot, ranger)
            if scan is None:
                assert packed is None
                skipped += 1
            else:
                np.testing.assert_array_equal(packed[0], scan[0])
                np.testing.assert_array_equal(packed[1], scan[1])
    assert skipped > 0  # the slow rangers skipped steps


AGAINST_A_WALL = """resolution 0.02
model( size [1 4 1] pose [1 0 0 0] )
position( size [0.4 0.4 0.2] pose [0 0 0 0] )
position( size [0.4 0.4 0.2] pose [-3 0 0 0] )
"""


def test_topics_reading_the_same_quantity_share_one_copy_and_derived_values_are_the_simulation_s() -> None:
    """odom and /tf share the odometry poses; ground truth's velocities, zero while stalled, are derived from the
    kept velocities and stall flags after the batch's trip (robots without rangers, no scan topic). The batch
    keeps the steps' arrays until it is sent: moving the stalled robot between steps (which clears its stall
    flag) leaves the steps before as they were."""
    sim = Simulation(load_world_text(AGAINST_A_WALL, "wall.world"), seed=0)
    stepped = [topics.ODOM, topics.GROUND_TRUTH, topics.TF]
    batch = StepBatch.first(sim, stepped, 12)
    expected = []
    for step in range(12):
        if step == 8:
            assert sim.stalled[0]
            sim.set_pose(0, 0.0, 0.0, 0.0)
        sim.set_velocity(0, 1.0, 0.0, 0.0)  # into the wall: it stalls
        sim.set_velocity(1, -0.5, 0.0, 0.2)
        sim.step()
        batch.capture(sim)
        expected.append((sim.sim_time_us, sim.odometry_poses.copy(), sim.true_poses.copy(), sim.true_velocities))
    received = travelled(batch)
    odometry, truth, tf = received.values()
    assert np.shares_memory(odometry[0], tf)
    np.testing.assert_array_equal(received.times, [time_us for time_us, *_ in expected])
    np.testing.assert_array_equal(tf, [poses for _, poses, *_ in expected])
    np.testing.assert_array_equal(truth[0], [poses for *_, poses, _ in expected])
    true_velocities = np.array([velocities for *_, velocities in expected])
    assert true_velocities.tobytes() == truth[1].tobytes()
    assert (true_velocities[:, 0] == 0.0).all(axis=1).any()  # the first robot stalled
    assert (true_velocities[:, 1, 0] == -0.5).all()  # the second did not
