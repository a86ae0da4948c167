"""The per-step messages refilled in their serialised bytes are the bytes rosbags serialises, for every
endpoint of every per-step topic (clock, odom, ground truth, stall, scans, tf), step after step."""

from __future__ import annotations

import pickle
from pathlib import Path

import pytest

from stage_sim.bags.messages import LAYOUTS, TOPIC_MESSAGES, TYPESTORE, _time, template
from stage_sim.bags.step_state import StepBatch
from stage_sim.interface import topics
from stage_sim.interface.topics import Timing
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world, load_world_text
from tests.bags.test_recorder import COMMANDS, names_of
from tests.bags.test_step_state import WORLD as RATES_WORLD
from tests.bags.test_step_state import travelled
from tests.bags.worlds import two_robot_world

STEPPED = [t for t in topics.PUBLISHED if t.timing is not Timing.START]


def test_every_per_step_topic_has_a_layout() -> None:
    assert set(LAYOUTS) == set(STEPPED)


def _world(name: str, tmp_path: Path) -> Simulation:
    if name == "rangers at different rates":
        return Simulation(load_world_text(RATES_WORLD, str(tmp_path / "rates.world")), seed=5)
    # the compiled kernels step this world in one fused call, whose beams the batch copies as they come
    return Simulation(load_world(two_robot_world(tmp_path)), seed=5,
                      kernels="numba" if name == "two robots, compiled" else "numpy")


@pytest.mark.parametrize("world", ["two robots", "two robots, compiled", "rangers at different rates"])
@pytest.mark.parametrize("chosen", ["every endpoint", "the last endpoints first"])
@pytest.mark.parametrize("topic", STEPPED, ids=lambda t: t.name)
def test_refilled_bytes_are_the_library_serialisation(tmp_path, topic, chosen, world) -> None:
    """Also with the endpoints recorded in another order than the simulation's (a bag of chosen topics):
    a topic's layout then gathers each one's values from where they are; and with rangers slower than the
    step, which skip steps, and a robot without any."""
    sim = _world(world, tmp_path)
    names = names_of(sim)
    endpoints = topics.endpoints(topic, names)
    if chosen != "every endpoint":
        endpoints = endpoints[::-1]
    # as the writer process gets them: pickled (a layout travels as its template)
    layout = pickle.loads(pickle.dumps(LAYOUTS[topic]([template(topic, e, sim, names) for e in endpoints], endpoints)))
    messages = [TOPIC_MESSAGES[topic].build(e, sim, names) for e in endpoints]
    for robot, command in enumerate(COMMANDS):
        if robot < len(sim.robots):
            sim.set_velocity(robot, *command)
    compared = 0
    for size in (5, 1, 4, 2):  # batches of several sizes, the layout's buffer grown and reused
        batch = StepBatch.first(sim, [topic], size)
        expected = []
        for _ in range(size):
            sim.step()
            batch.capture(sim)
            values, stamp = topic.values(sim, names), _time(sim.sim_time_us)
            filled = [TOPIC_MESSAGES[topic].fill(msg, values, e, stamp) for e, msg in zip(endpoints, messages,
                                                                                          strict=True)]
            expected.append([None if msg is None else bytes(TYPESTORE.serialize_cdr(msg, topic.msgtype))
                             for msg in filled])
        received = travelled(batch)
        (values,) = received.values()
        refilled = layout.refill(values, received.times)
        assert list(refilled) == [data for step in expected for data in step]  # step after step
        assert layout.count(values) == sum(data is not None for step in expected for data in step)
        compared += sum(data is not None for step in expected for data in step)
    assert compared >= 12 * len(endpoints) // 2  # scans too: the rangers measure in most steps
