"""The sensor registry: every registered world-file type name loads as its kind, simulated or said not to be."""

from __future__ import annotations

import pytest

from stage_sim.worldfile.errors import WorldError
from stage_sim.worldfile.loader import load_world_text
from stage_sim.worldfile.sensor_kinds import SENSOR_KINDS, SensorKind, robot_sensors

PLAIN_MODEL_SIZE = (0.4, 0.4, 1.0)


@pytest.mark.parametrize("kind", SENSOR_KINDS.values(), ids=list(SENSOR_KINDS))
def test_every_world_type_name_of_a_kind_loads_as_that_kind(kind: SensorKind) -> None:
    for name in kind.world_types:
        world = load_world_text(f"position( {name}( ) )", "/virtual/w.world")
        (robot,) = world.robots()
        (model,) = robot.children
        assert model.type == kind.type
        assert model.size == (kind.size or PLAIN_MODEL_SIZE)
        said_not_simulated = any(f"'{kind.type}' models are not simulated" in w.message for w in world.warnings)
        assert said_not_simulated is not kind.simulated
        assert robot_sensors(robot) == ([model] if kind.simulated else [])


def test_sensor_blocks_belong_only_to_kinds_that_read_them() -> None:
    readers = [kind for kind in SENSOR_KINDS.values() if kind.read is not None]
    assert [kind.type for kind in readers] == ["ranger"]
    with pytest.raises(WorldError, match="'sensor' outside a ranger"):
        load_world_text("camera( sensor( ) )", "/virtual/w.world")
