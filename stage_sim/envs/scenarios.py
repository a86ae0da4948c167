"""Scenario generators: which world an episode runs in, where its robots start and where their goals are.

* ``"random"``: a world (a ``.world`` file, or a generated walled arena) with starts and goals drawn from
  its free space (:mod:`stage_sim.envs.free_space`);
* ``"circle"``: circle crossing: N robots evenly spaced on a circle in an empty arena, each heading for
  the antipodal point, the circle turned by a random angle and every start and goal jittered;
* ``"obstacles"``: ``"random"`` plus ``n_obstacles`` static boxes drawn anew in every episode.

Every draw comes from the generator the environment seeds at reset, so a seed fixes the episode.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from stage_sim.envs.free_space import FreeSpace, PlacementError
from stage_sim.envs.worlds import RobotBody, WorldSource, obstacle_models, robots_text, world_centre
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.description import WorldDescription

KINDS = ("random", "circle", "obstacles")


@dataclass(frozen=True)
class ScenarioOptions:
    """Everything that chooses the episodes' worlds, robots, starts and goals (the envs' keyword arguments)."""

    scenario: str = "random"
    world: str | Path | None = None
    n_robots: int | None = None
    arena_size: float | None = None
    resolution: float = 0.05
    body: RobotBody = field(default_factory=RobotBody)
    circle_radius: float | None = None
    circle_jitter: float = 0.1
    n_obstacles: int = 8
    obstacle_size: tuple[float, float] = (0.3, 1.0)
    min_goal_distance: float = 2.0
    clearance: float = 0.1

    def __post_init__(self) -> None:
        if self.scenario not in KINDS:
            raise ValueError(f"unknown scenario {self.scenario!r} (choose from {', '.join(KINDS)})")
        if self.scenario == "circle" and self.world is not None:
            raise ValueError("the circle scenario runs in a generated arena: leave 'world' out")
        if self.n_robots is not None and self.n_robots < 1:
            raise ValueError(f"n_robots must be at least 1, got {self.n_robots}")

    @property
    def radius(self) -> float:
        """The circle's radius: given, else room for every robot with a body's width between neighbours."""
        if self.circle_radius is not None:
            return self.circle_radius
        return max(4.0, (self.n_robots or 1) * (4 * self.body.radius + 0.2) / (2 * math.pi))


class Scenario:
    """Builds the base world once and, per episode, its obstacles (if any), starts and goals.

    One scenario can serve several tasks (a vector env's worlds): what depends on the base world alone is worked
    out once for all of them (the base simulation of worlds that change per episode, the free space of the base
    world), and each simulation placed in gets its own free space, derived from the base's."""

    def __init__(self, options: ScenarioOptions) -> None:
        self.options = options
        arena = options.arena_size
        if arena is None:
            arena = 2 * options.radius + 3.0 if options.scenario == "circle" else 10.0
        self.source = WorldSource.of(options.world, arena, options.resolution)
        plain = self.source.load()
        generated = options.n_robots if options.n_robots is not None else (0 if plain.robots() else 1)
        robots = robots_text(generated, options.body, world_centre(plain)) if generated else ""
        self.base = self.source.load(robots, bool(options.n_robots)) if generated else plain
        self._base_space: FreeSpace | None = None
        self._root_space: FreeSpace | None = None
        # The free space of each simulation placed in, for as long as it lives (a task's current world).
        self._spaces: weakref.WeakKeyDictionary[Simulation, FreeSpace] = weakref.WeakKeyDictionary()

    @cached_property
    def simulation(self) -> Simulation:
        """The base world's simulation, shared by the tasks of this scenario and never stepped: every episode's
        world is made from it when :attr:`changes_world`, else each task's simulation of the base world (which
        shares its static parts)."""
        return Simulation(self.base)

    @property
    def changes_world(self) -> bool:
        """Whether every episode has a world of its own (new obstacles)."""
        return self.options.scenario == "obstacles" and self.options.n_obstacles > 0

    def world(self, rng: np.random.Generator, base_sim: Simulation) -> WorldDescription:
        """The world of the next episode: the base world, with fresh obstacles if the scenario has them."""
        if not self.changes_world:
            return self.base
        if self._base_space is None:
            self._base_space = FreeSpace(base_sim, list(range(len(base_sim.robots))), 0.0)
        low, high = self.options.obstacle_size
        boxes = np.empty((self.options.n_obstacles, 5))
        compiled = base_sim.starting_kernels() == "numba"  # the episode's kernels (the base stays on numpy)
        for i in range(len(boxes)):
            boxes[i, :2] = self._base_space.draw(rng, boxes[:i, :2], high, compiled=compiled)
            boxes[i, 2:4] = rng.uniform(low, high, 2)
            boxes[i, 4] = rng.uniform(-math.pi, math.pi)
        return self.source.add(self.base, obstacle_models(boxes, self.base.settings), bool(self.options.n_robots))

    def place(
        self, sim: Simulation, agents: list[int], rng: np.random.Generator
    ) -> tuple[np.ndarray, np.ndarray]:
        """Start poses (A, 3) and goals (A, 2) of the agents; other robots stay where the world put them."""
        if self.options.scenario == "circle":
            return self._circle(len(agents), rng)
        # The static world of a simulation never changes: its free space is worked out once. The first is the
        # base's (check_room places in it); the others (an episode's world: the base with obstacles added, or
        # another task's simulation of the base) are derived from it, redone only where they differ.
        space = self._spaces.get(sim)
        if space is None:
            if self._root_space is None:
                space = self._root_space = FreeSpace(sim, agents, self.options.clearance)
            else:
                space = self._root_space.with_world(sim)
            self._spaces[sim] = space
        others = np.array([r.start[:2] for r in sim.robots if r.index not in agents]).reshape(-1, 2)
        return space.starts_and_goals(rng, len(agents), others, self.options.min_goal_distance)

    def check_room(self, sim: Simulation, agents: list[int]) -> None:
        """Refuse, before any episode, a scenario whose world cannot hold its robots and their goals: one
        trial placement in the base world (raises PlacementError saying what does not fit)."""
        if self.options.scenario == "circle":
            return
        try:
            self.place(sim, agents, np.random.default_rng(0))
        except PlacementError as error:
            raise PlacementError(f"the {self.options.scenario!r} scenario cannot hold {len(agents)} robot(s) with "
                                 f"goals {self.options.min_goal_distance:g} m away in this world: {error}") from None

    def _circle(self, count: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        angles = rng.uniform(-math.pi, math.pi) + 2 * math.pi * np.arange(count) / count
        on_circle = self.options.radius * np.stack([np.cos(angles), np.sin(angles)], axis=-1)
        jitter = self.options.circle_jitter
        starts_xy = on_circle + rng.uniform(-jitter, jitter, (count, 2))
        goals = -on_circle + rng.uniform(-jitter, jitter, (count, 2))
        heading = np.arctan2(goals[:, 1] - starts_xy[:, 1], goals[:, 0] - starts_xy[:, 0])
        return np.column_stack([starts_xy, heading]), goals
