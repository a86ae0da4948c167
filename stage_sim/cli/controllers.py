"""Who drives the robots in a core-only run (``render``, and any subcommand that steps a simulation).

Each controller is set up once for a simulation and returns a callable to run before every step.
"""

from __future__ import annotations

from collections.abc import Callable

from stage_sim.sim.simulation import Simulation

STRAIGHT_SPEED = 0.3
"""m/s of ``render --controller straight``: every robot drives straight ahead until something stops it."""


def straight(sim: Simulation, seed: int | None) -> Callable[[], None]:
    """Every robot commanded straight ahead once (commands persist; the CLI's simulation has no watchdog)."""
    for robot in range(len(sim.robots)):
        sim.set_velocity(robot, STRAIGHT_SPEED, 0.0, 0.0)
    return lambda: None


def wander(sim: Simulation, seed: int | None) -> Callable[[], None]:
    """The ``wander`` node's reactive strategy on every robot's first laser (robots without one stay put)."""
    from stage_sim.runs.driver import WanderDriver

    return WanderDriver(sim, seed).decide


CONTROLLERS: dict[str, Callable[[Simulation, int | None], Callable[[], None]]] = {
    "straight": straight,
    "wander": wander,
}
