"""A world's warnings name each problem once per definition, however many robots share it."""

from __future__ import annotations

from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text

WORLD = """
define twin ranger ( sensor( range [0 2] samples 5 ) sensor( range [0 2] samples 5 ) )
define bot position ( size [0.3 0.3 0.2] twin( ) )
bot( pose [1 1 0 0] name "a" )
bot( pose [2 1 0 0] name "b" )
bot( pose [3 1 0 0] name "c" )
"""


def test_a_ranger_definition_with_several_sensors_is_reported_once_for_all_its_robots():
    sim = Simulation(load_world_text(WORLD, "twins.world"), seed=0, kernels="numpy")
    several = [w for w in sim.warnings if "sensors; like stageros only the first is simulated" in w.message]
    assert len(several) == 1
    assert several[0].message.endswith("(and 2 more rangers defined there)")
    assert several[0].location is not None and several[0].location.line == 3  # twin( ) inside the define of bot
    assert [len(r.rangers) for r in sim.robots] == [1, 1, 1]


NESTED = """
define mast model ( ranger( name "high" sensor( samples 5 ) ) )
define bot position ( size [0.3 0.3 0.2] ranger( sensor( samples 3 ) ) mast( ) )
bot( pose [1 1 0 0] name "a" )
bot( pose [2 1 0 0] name "b" )
"""


def test_a_ranger_not_directly_on_a_robot_is_dropped_with_one_located_warning():
    sim = Simulation(load_world_text(NESTED, "nested.world"), seed=0, kernels="numpy")
    assert [[ranger.name for ranger in robot.rangers] for robot in sim.robots] == [["a.ranger:0"], ["b.ranger:0"]]
    (stray,) = [w for w in sim.warnings if "is not simulated" in w.message]
    assert stray.message.startswith("ranger 'high' is not simulated: it sits on model 'a.model:0'")
    assert stray.message.endswith("(and 1 more defined here)")
    assert stray.location is not None and (stray.location.line, stray.location.column) == (2, 21)
