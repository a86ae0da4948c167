"""The per-step messages refilled in their serialised bytes are the bytes rosbags serialises, for every
endpoint of every per-step topic (clock, odom, ground truth, stall, scans, tf), step after step."""

from __future__ import annotations

import pickle

import pytest

from stage_sim.bags.messages import LAYOUTS, TOPIC_MESSAGES, TYPESTORE, _time, template
from stage_sim.bags.step_state import StepBatch
from stage_sim.interface import topics
from stage_sim.interface.topics import Timing
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world
from tests.bags.test_recorder import COMMANDS, names_of
from tests.bags.worlds import two_robot_world

STEPPED = [t for t in topics.PUBLISHED if t.timing is not Timing.START]


def test_every_per_step_topic_has_a_layout() -> None:
    assert set(LAYOUTS) == set(STEPPED)


@pytest.mark.parametrize("chosen", ["every endpoint", "the last endpoints first"])
@pytest.mark.parametrize("topic", STEPPED, ids=lambda t: t.name)
def test_refilled_bytes_are_the_library_serialisation(tmp_path, topic, chosen) -> None:
    """Also with the endpoints recorded in another order than the simulation's (a bag of chosen topics):
    a topic's layout then gathers each one's values from where they are."""
    sim = Simulation(load_world(two_robot_world(tmp_path)), seed=5)
    names = names_of(sim)
    endpoints = topics.endpoints(topic, names)
    if chosen != "every endpoint":
        endpoints = endpoints[::-1]
    # as the writer process gets them: pickled (a layout travels as its template)
    layout = pickle.loads(pickle.dumps(LAYOUTS[topic]([template(topic, e, sim, names) for e in endpoints], endpoints)))
    messages = [TOPIC_MESSAGES[topic].build(e, sim, names) for e in endpoints]
    for robot, command in enumerate(COMMANDS):
        sim.set_velocity(robot, *command)
    compared = 0
    for _ in range(12):
        sim.step()
        batch = StepBatch.first(sim, names, [topic], 1)
        batch.capture(sim, names, [topic])
        ((captured,),) = [state.values for state in pickle.loads(pickle.dumps(batch)).steps()]
        values = topic.values(sim, names)
        refilled_all = layout.refill(captured, sim.sim_time_us)
        assert layout.count(captured) == sum(data is not None for data in refilled_all)
        for endpoint, refilled, msg in zip(endpoints, refilled_all, messages, strict=True):
            filled = TOPIC_MESSAGES[topic].fill(msg, values, endpoint, _time(sim.sim_time_us))
            if filled is None:
                assert refilled is None
                continue
            assert refilled == TYPESTORE.serialize_cdr(filled, topic.msgtype), endpoint.name
            compared += 1
    assert compared >= 12 * len(endpoints) // 2  # scans too: the rangers measure in most steps
