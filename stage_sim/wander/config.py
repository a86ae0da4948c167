"""The wanderer's tunable parameters, in a module of their own so that every part of the wanderer can read them."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class WanderConfig:
    """Tunable parameters; the defaults suit the bundled worlds' course robot (0.46 × 0.3 m body)."""

    forward_speed: float = 0.7  # m/s in the open
    safety_distance: float = 0.04  # m kept between the body rectangle and any obstacle point
    turn_rate: float = 1.2  # rad/s at most
    holonomic: bool = False  # also try sideways commands (omni drive)
    # The body as rectangles (x_min, x_max, y_min, y_max) in the robot frame: chassis and laser housing.
    footprint: tuple[tuple[float, float, float, float], ...] = ((-0.2, 0.2, -0.15, 0.15), (0.2, 0.26, -0.03, 0.03))
    memory_radius: float = 1.5  # m around the robot within which out-of-view points are remembered
    moving_speed: float = 0.7  # m/s assumed for things seen moving in (other robots) when keeping clear of them
    tour_s: tuple[float, float] = (40.0, 120.0)  # duration range of a tour before its side is redrawn
    visit_reach: float = 1.0  # m around the path that counts as visited
    visit_memory_s: float = 3000.0  # s after which a visited place counts as new again
