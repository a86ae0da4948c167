"""The sensor types a world file can hold, registered in one place, and the rule for which belong to a robot.

Each :class:`SensorKind` says which world-file type names it answers to, the body a model of that type
gets by default, how its transducers are read and whether the simulation produces data for it. The loader,
``inspect`` and the simulation ask this module instead of naming sensor types themselves.

Which sensors belong to a robot is stageros' rule (:func:`robot_sensors`): the simulated sensors that are
*direct* children of a position model. A simulated sensor placed anywhere else is loaded but produces no
data, and the loader says so where it is written (:func:`stray_sensor_warnings`).

A new sensor type is an entry in :data:`SENSOR_KINDS` (with its reader beside :func:`ranger_sensors` in
:mod:`stage_sim.worldfile.sensors` if it has transducers); a simulated one also needs its spec built from
:func:`robot_sensors` in :mod:`stage_sim.sim.robots`, the readings the simulation computes each step, and
its message and topic on the ROS side.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

from stage_sim.worldfile.colors import RGBA
from stage_sim.worldfile.description import Model, Sensor, WorldWarning
from stage_sim.worldfile.errors import SourceLocation
from stage_sim.worldfile.keys import Properties
from stage_sim.worldfile.sensors import ranger_sensors

ROBOT_TYPE = "position"
"""The model type stageros makes a robot of."""

SensorReader = Callable[[Properties, list[Sensor], str, SourceLocation], list[Sensor]]
"""Reads a sensor model's transducers: its keys, its ``sensor( )`` blocks, the type written, where it is."""


@dataclass(frozen=True)
class SensorKind:
    """One sensor type: how a world file names it, what it is made of, whether it is simulated."""

    type: str
    """The model type it is stored as (:attr:`Model.type`)."""
    world_types: tuple[str, ...]
    """World-file type names read as this kind (Stage 3 names among them, read with a warning)."""
    size: tuple[float, float, float] | None = None
    """Default body size; None: a plain model's."""
    color: RGBA | None = None
    """Default colour; None: a plain model's."""
    read: SensorReader | None = None
    """Reads its transducers from ``sensor( )`` blocks; None: it takes no ``sensor( )`` blocks."""
    simulated: bool = False
    """The simulation produces data for it; otherwise it is loaded with a "not simulated" warning."""


SENSOR_KINDS: dict[str, SensorKind] = {
    kind.type: kind
    for kind in (
        SensorKind("ranger", ("ranger", "laser"), (0.15, 0.15, 0.2), (0.0, 0.0, 139 / 255, 1.0), ranger_sensors,
                   simulated=True),
        SensorKind("camera", ("camera",), size=(0.1, 0.07, 0.05)),
        SensorKind("fiducial", ("fiducial",)),
        SensorKind("blobfinder", ("blobfinder",)),
        SensorKind("bumper", ("bumper",)),
    )
}
"""Every sensor type, by the model type it is stored as."""

SENSOR_OF_WORLD_TYPE: dict[str, SensorKind] = {
    name: kind for kind in SENSOR_KINDS.values() for name in kind.world_types
}
"""The sensor kind each world-file type name creates."""


def is_simulated_sensor(model: Model) -> bool:
    """Whether ``model`` is a sensor the simulation produces data for (wherever it sits)."""
    kind = SENSOR_KINDS.get(model.type)
    return kind is not None and kind.simulated


def robot_sensors(robot: Model, sensor_type: str | None = None) -> list[Model]:
    """The simulated sensors of ``robot`` (of ``sensor_type`` only, if given): its direct children, as stageros."""
    return [
        child for child in robot.children
        if is_simulated_sensor(child) and (sensor_type is None or child.type == sensor_type)
    ]


def stray_sensor_warnings(models: list[Model]) -> list[WorldWarning]:
    """One warning per place a simulated sensor is written that no robot owns (it produces no data)."""
    strays: dict[SourceLocation | None, list[str]] = {}
    for model, parent in _with_parents(models):
        if not is_simulated_sensor(model) or (parent is not None and parent.type == ROBOT_TYPE):
            continue
        where = "at the top level" if parent is None else f"on {parent.type} '{parent.name}'"
        strays.setdefault(model.location, []).append(
            f"{model.type} '{model.name}' is not simulated: it sits {where}, and like stageros only the direct "
            f"children of a {ROBOT_TYPE} model are a robot's sensors")
    warnings = []
    for location, messages in strays.items():
        more = f" (and {len(messages) - 1} more defined here)" if len(messages) > 1 else ""
        warnings.append(WorldWarning(messages[0] + more, location))
    return warnings


def _with_parents(models: list[Model], parent: Model | None = None) -> Iterator[tuple[Model, Model | None]]:
    """Every model with its parent, in pre-order."""
    for model in models:
        yield model, parent
        yield from _with_parents(model.children, model)
