"""Worlds for the environments, written as Stage world text: a walled arena, disc robots, box obstacles.

Generated worlds go through :func:`load_world_text` like any file a user writes, so they are checked,
rasterised, simulated and rendered by the same code. A user's own ``.world`` can be extended the same
way: its text with generated robots appended, loaded as if it were that file (includes and bitmaps
resolve from its folder). An episode's obstacles, made anew at every reset, skip the text: they are the
very models the loader would make of it (:func:`obstacle_models`), added to the loaded world.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stage_sim.worldfile.bundled import find_world
from stage_sim.worldfile.colors import x11_color
from stage_sim.worldfile.description import Block, Model, Pose, WorldDescription, WorldSettings
from stage_sim.worldfile.loader import UNIT_SQUARE, load_world, load_world_text
from stage_sim.worldfile.syntax import read_text_file

#: Corners of the polygon that stands for a round robot body (Stage scales it to the model size).
DISC_CORNERS = 12
ROBOT_DEFINE = "rl_robot"
OBSTACLE_COLOR = "DarkSlateGray"


@dataclass(frozen=True)
class RobotBody:
    """The generated robot: a disc with a diff drive and one laser at its centre, seen by other lasers."""

    radius: float = 0.2
    height: float = 0.4
    max_speed: float = 1.0
    max_turn: float = math.pi / 2
    laser_samples: int = 512
    laser_fov: float = math.pi
    laser_range: float = 4.0

    def define_text(self) -> str:
        """A Stage ``define`` for this robot (forward-only speed: the laser does not look backwards)."""
        corners = " ".join(
            f"point[{i}] [{0.5 * math.cos(2 * math.pi * i / DISC_CORNERS):.6f} "
            f"{0.5 * math.sin(2 * math.pi * i / DISC_CORNERS):.6f}]"
            for i in range(DISC_CORNERS)
        )
        turn = math.degrees(self.max_turn)
        return (
            f"define {ROBOT_DEFINE} position (\n"
            f"  size [{2 * self.radius} {2 * self.radius} {self.height}] drive \"diff\" localization \"gps\"\n"
            f"  velocity_bounds [0 {self.max_speed} 0 0 0 0 {-turn} {turn}] obstacle_return 1 ranger_return 1\n"
            f"  block( points {DISC_CORNERS} {corners} z [0 1] )\n"
            f"  ranger( pose [0 0 {-self.height / 2} 0] size [0.01 0.01 0.01]\n"
            f"    sensor( range [0 {self.laser_range}] fov {math.degrees(self.laser_fov)}"
            f" samples {self.laser_samples} ) )\n"
            ")\n"
        )


def arena_text(size: float, resolution: float = 0.05, interval_sim: float = 0.1) -> str:
    """World settings and four walls round a ``size`` × ``size`` m square centred on the origin."""
    half, thick = size / 2, 0.1
    walls = [("north", 0.0, half, size + thick, thick), ("south", 0.0, -half, size + thick, thick),
             ("east", half, 0.0, thick, size + thick), ("west", -half, 0.0, thick, size + thick)]
    lines = [f"resolution {resolution}", f"interval_sim {round(interval_sim * 1000)}",
             f"window( size [600 600] center [0 0] scale {600 / (size + 1):.3f} show_data 1 )"]
    lines += [f'model( name "wall_{name}" size [{w} {h} 1] pose [{x} {y} 0 0] color "gray30" obstacle_return 1 )'
              for name, x, y, w, h in walls]
    return "\n".join(lines) + "\n"


def robots_text(count: int, body: RobotBody, at: tuple[float, float] = (0.0, 0.0)) -> str:
    """``count`` generated robots named ``agent_<i>``, stacked at ``at`` until a scenario places them."""
    x, y = at
    robots = [f'{ROBOT_DEFINE}( name "agent_{i}" pose [{x:.4f} {y:.4f} 0 0] color "{_robot_color(i)}" )'
              for i in range(count)]
    return body.define_text() + "\n".join(robots) + "\n"


def world_centre(description: WorldDescription) -> tuple[float, float]:
    """Middle of the top-level static models' boxes: a place inside the world for robots not yet placed
    (the simulation's grid grows to hold every robot, so a far-off origin would make it needlessly big)."""
    boxes = [(m.pose.x - m.size[0] / 2, m.pose.y - m.size[1] / 2, m.pose.x + m.size[0] / 2, m.pose.y + m.size[1] / 2)
             for m in description.models if m.type != "position"]
    if not boxes:
        return (0.0, 0.0)
    low_x, low_y, _, _ = np.min(boxes, axis=0)
    _, _, high_x, high_y = np.max(boxes, axis=0)
    return (float(low_x + high_x) / 2, float(low_y + high_y) / 2)


def obstacles_text(boxes: np.ndarray) -> str:
    """Static boxes, one row (x, y, width, depth, yaw) each, as world text (4 decimals, yaw in degrees): a world
    whose boxes stay put from one episode to the next (the ``"random"`` scenario of a file holding them), where
    the ``"obstacles"`` scenario makes the same models anew at every reset (:func:`obstacle_models`)."""
    rows = enumerate(np.reshape(boxes, (-1, 5)).tolist())
    return "".join(
        f'model( name "obstacle_{i}" size [{w:.4f} {d:.4f} 1] pose [{x:.4f} {y:.4f} 0 {math.degrees(a):.4f}] '
        f'color "{OBSTACLE_COLOR}" obstacle_return 1 )\n' for i, (x, y, w, d, a) in rows)


def obstacle_models(boxes: np.ndarray, settings: WorldSettings) -> list[Model]:
    """Static boxes, one row (x, y, width, depth, yaw) each, as ordinary obstacle models: the models the loader
    makes of their :func:`obstacles_text` appended to the world's text, without writing or parsing it (a reset
    builds one world per episode). Like that text they hold 4 decimals (yaw in degrees) and are read in the
    world's units."""
    length, angle = settings.unit_length, settings.unit_angle
    color = x11_color(OBSTACLE_COLOR)
    models = []
    for i, (x, y, w, d, a) in enumerate(np.asarray(boxes).reshape(-1, 5)):
        x, y, w, d, yaw = (float(f"{value:.4f}") for value in (x, y, w, d, math.degrees(a)))
        models.append(Model(
            type="model", name=f"obstacle_{i}", pose=Pose(x * length, y * length, 0.0 * length, yaw * angle),
            size=(w * length, d * length, 1.0 * length), color=color,
            blocks=[Block(UNIT_SQUARE.copy(), (0.0, 1.0), None)], obstacle_return=True))
    return models


@dataclass(frozen=True)
class WorldSource:
    """Where a world comes from: a file (path or bundled name) or a generated empty arena."""

    path: Path | None = None
    arena_size: float = 10.0
    resolution: float = 0.05

    @classmethod
    def of(cls, world: str | Path | None, arena_size: float, resolution: float) -> WorldSource:
        """Resolve a user's ``world`` argument (None: the generated arena)."""
        if world is None:
            return cls(None, arena_size, resolution)
        return cls(find_world(world).resolve(), arena_size, resolution)

    def load(self, extra: str = "", replace_robots: bool = False) -> WorldDescription:
        """The world with ``extra`` text appended; ``replace_robots`` drops the file's own top-level robots."""
        if self.path is None:
            description = load_world_text(arena_text(self.arena_size, self.resolution) + extra, "arena.world")
        elif extra:
            description = load_world_text(read_text_file(self.path) + "\n" + extra, self.path)
        else:
            description = load_world(self.path)
        if replace_robots:
            generated = [m for m in description.models if m.type == "position" and m.name.startswith("agent_")]
            description.models = [m for m in description.models if m.type != "position"] + generated
        return description

    @staticmethod
    def add(description: WorldDescription, models: list[Model], replace_robots: bool = False) -> WorldDescription:
        """A loaded world (:meth:`load`) with ``models`` added where the text written after the file's would put
        them: after its models, before the generated robots that ``replace_robots`` moves to the end."""
        if replace_robots:
            ordered = [m for m in description.models if m.type != "position"] + models
            ordered += [m for m in description.models if m.type == "position"]
        else:
            ordered = [*description.models, *models]
        return WorldDescription(description.path, description.settings, ordered, list(description.warnings))


def _robot_color(index: int) -> str:
    palette = ("red", "blue", "green3", "orange", "magenta", "cyan3", "gold", "purple")
    return palette[index % len(palette)]
