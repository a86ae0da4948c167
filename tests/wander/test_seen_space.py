"""The map of seen space: which cells a scan frees and marks occupied, and routes through what was seen."""

from __future__ import annotations

import math

import numpy as np

from stage_sim.wander.seen_space import SeenSpace, route_heading

# Two rooms split by a wall at x = 2 (y from -3 to 3) with a door between y = 1.0 and y = 1.6, in a 6 x 6 box.
DOOR = (1.0, 1.6)
WALLS = [(2.0, -3.0, 2.0, DOOR[0]), (2.0, DOOR[1], 2.0, 3.0),
         (-1.0, -3.0, 5.0, -3.0), (-1.0, 3.0, 5.0, 3.0), (-1.0, -3.0, -1.0, 3.0), (5.0, -3.0, 5.0, 3.0)]


def cast(origin: tuple[float, float], walls: list[tuple[float, float, float, float]], beams: int = 720,
         range_max: float = 8.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A full-circle scan from ``origin`` against wall segments: origin, beam ends and which beams hit."""
    angles = np.arange(beams) * 2 * math.pi / beams
    d = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    o = np.array(origin)
    ranges = np.full(beams, range_max)
    for x0, y0, x1, y1 in walls:
        a, e = np.array([x0, y0]) - o, np.array([x1 - x0, y1 - y0])
        denom = d[:, 0] * e[1] - d[:, 1] * e[0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (a[0] * e[1] - a[1] * e[0]) / denom
            u = (a[0] * d[:, 1] - a[1] * d[:, 0]) / denom
        hit = (np.abs(denom) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
        ranges = np.where(hit & (t < ranges), t, ranges)
    return o, o + ranges[:, None] * d, ranges < range_max


def score_at(space: SeenSpace, x: float, y: float) -> int:
    i, j = space.index(np.array([x, y]))
    return int(space.score[i, j])


def test_a_beam_frees_the_cells_it_crosses_and_marks_the_one_it_ends_in() -> None:
    space = SeenSpace(cell=0.1, extent=20.0)
    space.observe(np.array([0.05, 0.05]), np.array([[2.05, 0.05]]), np.array([True]))
    assert all(score_at(space, x, 0.05) < 0 for x in np.arange(0.15, 1.9, 0.1))
    assert score_at(space, 2.05, 0.05) > 0
    assert score_at(space, 2.55, 0.05) == 0  # beyond the hit: unknown
    assert score_at(space, 1.05, 0.55) == 0  # beside the beam: unknown


def test_a_beam_that_reached_its_limit_frees_its_end_cell_too() -> None:
    space = SeenSpace(cell=0.1, extent=20.0)
    space.observe(np.array([0.05, 0.05]), np.array([[1.05, 0.05]]), np.array([False]))
    assert score_at(space, 1.05, 0.05) < 0


def test_where_the_body_stands_counts_as_free() -> None:
    space = SeenSpace(cell=0.1, extent=20.0)
    body = np.array([[x, y] for x in (-0.15, -0.05, 0.05, 0.15) for y in (-0.05, 0.05)])
    space.observe(np.array([0.25, 0.05]), np.array([[1.25, 0.05]]), np.array([True]), body)
    assert all(score_at(space, x, y) < 0 for x, y in body)
    assert score_at(space, -0.25, 0.05) == 0


def test_later_scans_outweigh_a_misplaced_wall() -> None:
    space = SeenSpace(cell=0.1, extent=20.0)
    wall = (np.array([0.05, 0.05]), np.array([[1.05, 0.05]]), np.array([True]))
    through = (np.array([0.05, 0.05]), np.array([[3.05, 0.05]]), np.array([True]))
    for _ in range(5):
        space.observe(*wall)
    assert score_at(space, 1.05, 0.05) > 0
    for _ in range(20):
        space.observe(*through)
    assert score_at(space, 1.05, 0.05) < 0


def seen_two_rooms() -> SeenSpace:
    """The two rooms as seen from the left room's middle and from in front of the door."""
    space = SeenSpace(cell=0.1, extent=20.0)
    for origin in [(0.5, 0.0), (1.5, -2.0), (1.6, 1.3), (0.5, 2.0)]:
        space.observe(*cast(origin, WALLS))
    return space


def test_the_route_to_the_far_room_goes_through_the_door() -> None:
    space = seen_two_rooms()
    route = space.route((0.5, -1.5), lambda xy: xy[:, 0] > 2.5)
    assert route is not None
    assert np.allclose(np.abs(np.diff(route, axis=0)).sum(axis=1), 0.1)  # cell to adjacent cell
    assert np.hypot(*(route[0] - (0.55, -1.45))) < 1e-9  # starts in the robot's cell
    assert route[-1, 0] > 2.5
    at_wall = route[np.isclose(route[:, 0], 2.05)]  # the column of cells the wall's hits fall in
    assert len(at_wall) and np.all((at_wall[:, 1] > DOOR[0]) & (at_wall[:, 1] < DOOR[1]))
    # Breadth-first over 4-connected cells: no shorter route exists than the Manhattan detour via the door.
    assert len(route) - 1 >= round((abs(2.5 - 0.55) + abs(1.05 + 1.45)) / 0.1)


def test_no_route_when_nothing_wanted_was_seen_or_can_be_reached() -> None:
    space = seen_two_rooms()
    assert space.route((0.5, -1.5), lambda xy: np.zeros(len(xy), dtype=bool)) is None
    assert space.route((0.5, -1.5), lambda xy: xy[:, 0] > 5.5) is None  # outside the walls: never seen free
    assert SeenSpace().route((0.0, 0.0), lambda xy: np.ones(len(xy), dtype=bool)) is None  # nothing seen yet


def test_a_lone_wanted_cell_is_not_worth_a_trip() -> None:
    space = seen_two_rooms()
    lone = space.centre(space.index(np.array([0.0, -2.0])))
    assert space.route((0.5, -1.5), lambda xy: np.all(np.isclose(xy, lone), axis=1)) is None
    patch = space.route((0.5, -1.5), lambda xy: np.hypot(xy[:, 0], xy[:, 1] + 2.0) < 0.3)
    assert patch is not None and np.hypot(patch[-1, 0], patch[-1, 1] + 2.0) < 0.4


def test_route_heading_aims_ahead_along_the_route() -> None:
    route = np.array([[x, 0.0] for x in np.arange(0.0, 2.01, 0.1)] + [[2.0, y] for y in np.arange(0.1, 2.01, 0.1)])
    heading, off = route_heading(route, (0.0, 0.5, 0.0), 1.0)
    assert math.isclose(heading, math.atan2(-0.5, 1.0), abs_tol=1e-9) and math.isclose(off, 0.5)
    heading, off = route_heading(route, (1.5, 0.0, math.pi / 2), 1.0)
    assert math.isclose(heading, math.atan2(0.5, 0.5) - math.pi / 2, abs_tol=1e-9) and off < 1e-9
