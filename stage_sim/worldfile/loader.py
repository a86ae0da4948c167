"""Stage world file → :class:`WorldDescription`: defines expanded, units converted, defaults applied.

Stage semantics kept (spec §7–§8): a define's properties apply base-most first, then each derived define,
then the instance (later wins); children of every level accumulate; a define named like a built-in type
shadows it from that point of the file on (``define block model`` turns later ``block(...)`` into child
models). Model names default to Stage's tokens ``type:k`` / ``parent.type:k``.

Where Stage 4 would silently misread or refuse a world, this loader reads it the way its author meant
and says so in a warning: Stage 3 ``laser`` and ``wifi`` models, ``size3``/``origin3``, 3-element poses,
2-element sizes, and a ranger that has ``range``/``fov``/``samples``/``noise`` on the ranger itself but no
``sensor( )`` block (Stage 4 ignores those keys; here they become the ranger's single sensor). Keys Stage 4
ignores (``range_max`` inside a ranger, ``laser_return``, ``interval_real`` ...) stay ignored, with a warning.
Any error raises
:class:`WorldError`; nothing half-loaded is returned.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stage_sim.worldfile.bitmap_files import BitmapFiles
from stage_sim.worldfile.bundled import find_world
from stage_sim.worldfile.description import (
    Block,
    Model,
    Pose,
    Sensor,
    WindowSettings,
    WorldDescription,
    WorldSettings,
)
from stage_sim.worldfile.errors import SourceLocation, WorldError
from stage_sim.worldfile.keys import (
    ANGLE_UNITS,
    LENGTH_UNITS,
    MODEL_ALIASES,
    MODEL_IGNORED,
    WINDOW_IGNORED,
    WORLD_IGNORED,
    Properties,
    Units,
    Warnings,
)
from stage_sim.worldfile.sensor_kinds import ROBOT_TYPE, SENSOR_KINDS, SENSOR_OF_WORLD_TYPE, stray_sensor_warnings
from stage_sim.worldfile.sensors import position_settings, read_sensor
from stage_sim.worldfile.syntax import (
    Define,
    Entity,
    Property,
    Reader,
    WorldSyntax,
    parse_world,
    parse_world_text,
    read_text_file,
)

MODEL_TYPES = frozenset(
    {"model", ROBOT_TYPE, "gripper", "actuator", "blinkenlight", "lightindicator", "wifi", *SENSOR_KINDS}
)  # fmt: skip
"""Stage 4's model types, and Stage 3's ``wifi`` (its wifi worlds are still in Stage's tree)."""
NOT_SIMULATED = MODEL_TYPES - {"model", ROBOT_TYPE} - {kind.type for kind in SENSOR_KINDS.values() if kind.simulated}
"""Read (bodies, names, poses) and ignored with one warning per type and world; they produce no data."""
BODY_TYPES = frozenset({"model", ROBOT_TYPE})
"""Types that get Stage's default unit-square body when they have neither ``block`` nor ``bitmap``."""
BUILTIN_TYPES = MODEL_TYPES | {"window", "block", "sensor", *SENSOR_OF_WORLD_TYPE}
MAX_MODELS = 100_000
MAX_DEPTH = 100
UNIT_SQUARE = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
"""Stage's default body (scaled to the model's size): the one block of a model given neither blocks nor a bitmap."""


def load_world(path: str | Path, reader: Reader = read_text_file) -> WorldDescription:
    """Load the world file at ``path`` (or the bundled world of that name) with its includes and bitmaps.

    A path that is not a file is looked up among the bundled worlds (``rooms`` or ``rooms.world``), as the
    command line does; :class:`~stage_sim.worldfile.bundled.WorldNotFoundError` says what was tried.
    """
    return _Loader(parse_world(find_world(path), reader)).load()


def load_world_text(text: str, path: str | Path = "world.world", reader: Reader = read_text_file) -> WorldDescription:
    """Load ``text`` as if it were the file ``path`` (includes and bitmaps resolve from its directory)."""
    return _Loader(parse_world_text(text, path, reader)).load()


@dataclass(frozen=True)
class _Instance:
    """An entity with its defines applied: built-in type, merged properties and accumulated children."""

    type: str
    location: SourceLocation
    properties: list[Property]
    children: list[Entity]
    defines: frozenset[str]
    """Names of the defines this instance and its ancestors came from (a define containing itself loops)."""


class _Loader:
    """One load: walks the syntax tree in file order, keeping the defines seen so far."""

    def __init__(self, syntax: WorldSyntax) -> None:
        self.syntax = syntax
        self.warnings = Warnings()
        self.units = Units()
        self.macros: dict[str, Define] = {}
        self.bitmaps = BitmapFiles(syntax.path)
        self.names: set[str] = set()
        self.model_count = 0
        self.not_simulated: dict[str, list[SourceLocation]] = {}
        """Where each model of a type this simulator ignores was read, to warn once per type."""

    def load(self) -> WorldDescription:
        world = Properties(self.syntax.properties, self.units, self.warnings)
        length_unit = world.choice("unit_length", "m", LENGTH_UNITS)
        angle_unit = world.choice("unit_angle", "degrees", ANGLE_UNITS)
        self.units = world.units = Units(LENGTH_UNITS[length_unit], ANGLE_UNITS[angle_unit])
        window: WindowSettings | None = None
        models: list[Model] = []
        counters: Counter[str] = Counter()
        for item in self.syntax.items:
            if isinstance(item, Define):
                if item.name in self.macros:
                    self.warnings.add(f"define '{item.name}' redefined; later uses get this one", item.location)
                self.macros[item.name] = item
                continue
            instance = self._expand(item, frozenset())
            if instance.type == "window":
                if window is None:
                    window = self._window(instance)
                else:
                    self.warnings.add("only the first window is used; this one is ignored", instance.location)
            elif instance.type in ("block", "sensor"):
                owner = "a model" if instance.type == "block" else "a ranger"
                raise WorldError(
                    f"'{instance.type}' outside {owner}",
                    instance.location,
                    found="it at top level",
                    expected=f"it inside {owner}",
                )
            else:
                models.append(self._model(instance, None, counters, 0))
        settings = self._settings(world, window)
        for kind, locations in self.not_simulated.items():
            more = f"; {len(locations)} in this world, the first here" if len(locations) > 1 else ""
            self.warnings.add(f"'{kind}' models are not simulated (loaded, but produce no data){more}", locations[0])
        for warning in stray_sensor_warnings(models):
            self.warnings.add(warning.message, warning.location)
        return WorldDescription(self.syntax.path, settings, models, self.warnings.items)

    def _settings(self, world: Properties, window: WindowSettings | None) -> WorldSettings:
        settings = WorldSettings(
            name=world.string("name", self.syntax.path.name),
            resolution=world.number("resolution", 0.02),
            interval_sim=world.number("interval_sim", 100.0) / 1000.0,
            quit_time=world.number("quit_time", 0.0),
            speedup=world.number("speedup", 1.0),
            threads=max(1, world.integer("threads", 1)),
            unit_length=self.units.length,
            unit_angle=self.units.angle,
            window=window,
        )
        if "resolution" in world:
            world.require(settings.resolution > 0, "resolution", settings.resolution, "a cell size > 0 m")
        if "interval_sim" in world:
            world.require(settings.interval_sim > 0, "interval_sim", settings.interval_sim * 1000, "> 0 ms")
        world.report_unread("the world", WORLD_IGNORED)
        return settings

    def _expand(self, entity: Entity, defines: frozenset[str]) -> _Instance:
        """Resolve ``entity.type`` through the defines seen so far down to a built-in type."""
        chain: list[Define] = []
        base = entity.type
        while base in self.macros and base not in (d.name for d in chain):
            chain.append(self.macros[base])
            base = chain[-1].parent
        names = [d.name for d in chain]
        if base not in BUILTIN_TYPES:
            if base in names:
                cycle = " -> ".join([*names, base])
                raise WorldError(
                    f"define cycle: {cycle}",
                    entity.location,
                    found=f"'{entity.type}'",
                    expected="defines that end in a built-in type",
                )
            raise WorldError(
                f"unknown entity type '{base}'",
                entity.location,
                found=f"'{entity.type}'",
                expected="a model type (model, position, ranger, ...) or a define",
            )
        looping = defines.intersection(names)
        if looping:
            raise WorldError(
                f"define '{sorted(looping)[0]}' contains itself",
                entity.location,
                found=f"'{entity.type}' inside its own define",
                expected="a finite model tree",
            )
        properties = [p for d in reversed(chain) for p in d.body.properties] + entity.properties
        children = [c for d in reversed(chain) for c in d.body.children] + entity.children
        return _Instance(base, entity.location, properties, children, defines.union(names))

    def _model(self, instance: _Instance, parent: Model | None, counters: Counter[str], depth: int) -> Model:
        self.model_count += 1
        if self.model_count > MAX_MODELS or depth > MAX_DEPTH:
            raise WorldError(
                "world too large",
                instance.location,
                found="more models or deeper nesting",
                expected=f"at most {MAX_MODELS} models nested at most {MAX_DEPTH} deep",
            )
        sensor_kind = SENSOR_OF_WORLD_TYPE.get(instance.type)
        kind = sensor_kind.type if sensor_kind is not None else instance.type
        props = Properties(instance.properties, self.units, self.warnings, MODEL_ALIASES)
        token = f"{kind}:{counters[kind]}"
        counters[kind] += 1
        name = props.string("name", token if parent is None else f"{parent.name}.{token}")
        if name in self.names:
            self.warnings.add(f"model name '{name}' is used more than once", instance.location)
        self.names.add(name)
        model = Model(type=kind, name=name, location=instance.location)
        self._model_keys(model, props, top_level=parent is None)
        sensors = self._children(model, instance, depth)
        if sensor_kind is not None and sensor_kind.read is not None:
            model.sensors = sensor_kind.read(props, sensors, instance.type, instance.location)
        if kind == ROBOT_TYPE:
            model.position = position_settings(props)
        if kind in BODY_TYPES and not model.blocks and model.bitmap is None:
            model.blocks.append(Block(UNIT_SQUARE.copy(), (0.0, 1.0), None))
        if kind in NOT_SIMULATED:
            self.not_simulated.setdefault(kind, []).append(instance.location)
        else:
            props.report_unread(f"a {kind} model", MODEL_IGNORED)
        return model

    def _model_keys(self, model: Model, props: Properties, top_level: bool) -> None:
        """The keys every model type has (spec §8.5)."""
        model.pose = props.pose("pose", Pose()) or Pose()
        sensor_kind = SENSOR_KINDS.get(model.type)
        default_size = (sensor_kind and sensor_kind.size) or (0.4, 0.4, 1.0)
        size = props.size(default_size[2])
        if size is not None:
            props.require(min(size) >= 0, "size", list(size), "sizes >= 0")
        model.size = size or default_size
        model.origin = props.pose("origin", Pose()) or Pose()
        model.color = props.color((sensor_kind and sensor_kind.color) or (1.0, 0.0, 0.0, 1.0))
        model.boundary = props.flag("boundary", False)
        model.obstacle_return = props.flag("obstacle_return", True)
        model.ranger_return = props.number("ranger_return", 1.0)
        model.update_interval = props.number("update_interval", 100.0) / 1000.0
        if "update_interval" in props:
            props.require(model.update_interval > 0, "update_interval", model.update_interval * 1000, "> 0 ms")
        model.stack_children = props.flag("stack_children", True)
        model.gui_nose = props.flag("gui_nose", False)
        model.gui_outline = props.flag("gui_outline", False)
        model.gui_grid = props.flag("gui_grid", False)
        model.gui_move = props.flag("gui_move", top_level)
        for key, why in (("velocity", "robots start at rest"), ("ctrl", "controller plugins are not loaded")):
            prop = props.take(key)
            if prop is not None:
                self.warnings.add(f"'{key}' is not supported and ignored: {why}", prop.location)
        bitmap = props.take("bitmap")
        if bitmap is not None:
            model.bitmap = self.bitmaps.load(bitmap, props.string("bitmap", ""))
            self._warn_if_trimmed(model)

    def _children(self, model: Model, instance: _Instance, depth: int) -> list[Sensor]:
        """Blocks and child models go into ``model``; sensors are returned for the ranger to sort out."""
        sensors: list[Sensor] = []
        counters: Counter[str] = Counter()
        for entity in instance.children:
            child = self._expand(entity, instance.defines)
            if child.type == "block":
                model.blocks.append(self._block(child))
            elif child.type == "sensor":
                if model.type not in SENSOR_KINDS or SENSOR_KINDS[model.type].read is None:
                    raise WorldError(
                        "'sensor' outside a ranger",
                        child.location,
                        found=f"it inside a {model.type} model",
                        expected="it inside a ranger",
                    )
                _no_children(child)
                sensors.append(read_sensor(Properties(child.properties, self.units, self.warnings)))
            elif child.type == "window":
                raise WorldError(
                    "'window' inside a model",
                    child.location,
                    found=f"it inside '{model.name}'",
                    expected="window at top level",
                )
            else:
                model.children.append(self._model(child, model, counters, depth + 1))
        return sensors

    def _block(self, instance: _Instance) -> Block:
        """``block( points N point[0] [x y] ... z [zmin zmax] )``, points in order as written."""
        _no_children(instance)
        props = Properties(instance.properties, self.units, self.warnings)
        if "points" not in props:
            raise WorldError(
                "block without 'points'",
                instance.location,
                found="no points key",
                expected="points N and point[0] ... point[N-1]",
            )
        count = props.integer("points", 0)
        props.require(count >= 3, "points", count, "at least 3 points")
        given = sum(1 for p in props.unread() if p.name.startswith("point["))
        points = []
        for i in range(count):
            key = f"point[{i}]"
            if key not in props:
                raise WorldError(
                    f"block is missing {key}",
                    props.location("points"),
                    found=f"{given} points",
                    expected=f"{count} points (point[0] ... point[{count - 1}])",
                )
            points.append(props.lengths(key, 2))
        z = props.lengths("z", 2) or (0.0, 1.0)
        if "z" in props:
            props.require(z[0] <= z[1], "z", list(z), "[zmin zmax] with zmin <= zmax")
        props.color((1.0, 0.0, 0.0, 1.0))  # per-block colours are accepted but not modelled
        for prop in props.unread():
            if prop.name.startswith("point["):
                self.warnings.add(f"{prop.name} ignored: the block declares points {count}", prop.location)
                props.take(prop.name)
        props.report_unread("a block")
        return Block(np.array(points, dtype=float), (z[0], z[1]), instance.location)

    def _warn_if_trimmed(self, model: Model) -> None:
        """Stage stretches only the occupied pixels' bounding box to ``size``: say so when margins are cut."""
        from stage_sim.worldfile.bitmap import occupied_bounding_box

        bitmap = model.bitmap
        if bitmap is None or bitmap.grid is not None:
            return
        height, width = bitmap.occupied.shape
        box = occupied_bounding_box(bitmap.occupied)
        if box is None or (box.row1 - box.row0, box.col1 - box.col0) == (height, width):
            return
        used_w, used_h = box.col1 - box.col0, box.row1 - box.row0
        self.warnings.add(
            f"bitmap {bitmap.path.name}: only its occupied pixels ({used_w}x{used_h} of {width}x{height}) are "
            f"stretched to size [{model.size[0]:g} {model.size[1]:g}], as in Stage, so a pixel spans "
            f"{model.size[0] / used_w:.5f} x {model.size[1] / used_h:.5f} m instead of "
            f"{model.size[0] / width:.5f} x {model.size[1] / height:.5f} m; add dark corner pixels to keep the scale",
            bitmap.location,
        )

    def _window(self, instance: _Instance) -> WindowSettings:
        _no_children(instance)
        props = Properties(instance.properties, self.units, self.warnings)
        defaults = WindowSettings()
        size = props.numbers("size", 2) or defaults.size
        center = props.numbers("center", 2) or defaults.center
        rotate = props.numbers("rotate", 2, [math.pi / 180.0] * 2) or defaults.rotate
        window = WindowSettings(
            size=(size[0], size[1]),
            center=(center[0], center[1]),
            rotate=(rotate[0], rotate[1]),
            scale=props.number("scale", defaults.scale),
            show_data=props.flag("show_data", defaults.show_data),
            show_trails=props.flag("show_trails", defaults.show_trails),
            show_grid=props.flag("show_grid", defaults.show_grid),
        )
        props.report_unread("the window", WINDOW_IGNORED)
        return window


def _no_children(instance: _Instance) -> None:
    if instance.children:
        child = instance.children[0]
        raise WorldError(
            f"'{instance.type}' cannot contain entities",
            child.location,
            found=f"'{child.type}( )'",
            expected=f"only properties inside {instance.type}( )",
        )
