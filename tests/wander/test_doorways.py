"""Narrow doorways found in scans, and the wanderer taking one into a room it has not seen."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from stage_sim.wander.doorways import DoorPassage, find_doorways
from stage_sim.wander.reactive import DOOR_BEYOND, Wanderer
from tests.wander.test_reactive import closed_loop, scan_of_segments

WIDTHS = (0.40, 0.69)  # what the wanderer asks for with the course robot: narrower than explore and tour see


def wall_with_gap(axis_point: float, gap: tuple[float, float], span: float, vertical: bool) -> list[tuple]:
    """Two wall segments leaving a gap, as (x0, y0, x1, y1): vertical walls sit at x = axis_point."""
    pieces = [(-span, gap[0]), (gap[1], span)]
    if vertical:
        return [(axis_point, a, axis_point, b) for a, b in pieces]
    return [(a, axis_point, b, axis_point) for a, b in pieces]


def test_a_door_straight_ahead() -> None:
    segments = [*wall_with_gap(2.0, (0.1, 0.55), 4.0, vertical=True), (5.0, -4.0, 5.0, 4.0)]
    (door,) = find_doorways(scan_of_segments(segments), *WIDTHS)
    np.testing.assert_allclose(door.center, [2.0, 0.325], atol=0.02)
    np.testing.assert_allclose(door.normal, [1.0, 0.0], atol=0.02)
    assert 0.45 <= door.width <= 0.45 + 2 * 0.035  # the jambs are the last hits: up to a beam's spacing wide


def test_a_door_seen_obliquely_in_a_side_wall() -> None:
    """The far jamb shows its face (the wall's thickness) at a slant; the wall beside the near jamb gives
    the true direction, so the width and centre stay right."""
    segments = [(-1.0, -0.6, 1.5, -0.6), (1.95, -0.6, 6.0, -0.6),  # the wall's near face, door from 1.5 to 1.95
                (1.95, -0.6, 1.95, -0.75),  # the far jamb's face, 15 cm of wall thickness
                (-1.0, -3.0, 6.0, -3.0)]  # the room's far wall
    (door,) = find_doorways(scan_of_segments(segments), *WIDTHS)
    np.testing.assert_allclose(door.center, [1.725, -0.6], atol=0.03)
    np.testing.assert_allclose(door.normal, [0.0, -1.0], atol=0.05)
    assert 0.45 - 0.02 <= door.width <= 0.45 + 0.07


@pytest.mark.parametrize(("gap", "back"), [((0.0, 1.1), 5.0), ((0.0, 0.3), 5.0), ((0.0, 0.45), 2.3)])
def test_wide_openings_narrow_slits_and_niches_are_not_doorways(gap: tuple[float, float], back: float) -> None:
    segments = [*wall_with_gap(2.0, gap, 4.0, vertical=True), (back, -4.0, back, 4.0)]
    assert find_doorways(scan_of_segments(segments), *WIDTHS) == []


def test_passage_steers_onto_the_axis_and_knows_when_it_is_through() -> None:
    segments = [*wall_with_gap(2.0, (-0.225, 0.225), 4.0, vertical=True), (5.0, -4.0, 5.0, 4.0)]
    (door,) = find_doorways(scan_of_segments(segments), *WIDTHS)
    passage = DoorPassage.seen_from(door, (1.0, 1.0, math.pi / 2), until=30.0)  # robot at (1, 1) facing +y
    np.testing.assert_allclose(passage.center, [1.0, 3.0], atol=0.02)
    np.testing.assert_allclose(passage.normal, [0.0, 1.0], atol=0.02)
    assert passage.heading((1.0, 1.0, 0.0)) == pytest.approx(math.pi / 2, abs=0.02)  # on the axis: straight
    assert passage.heading((1.5, 1.0, 0.0)) > math.pi / 2 + 0.3  # right of the axis: steer left onto it
    along, lateral = passage.progress((1.0, 3.7, 0.0))
    assert along == pytest.approx(0.7, abs=0.02) and lateral == pytest.approx(0.0, abs=0.02)


CORRIDOR_AND_ROOM = """
wall( size [8 0.1 1] pose [4 2.05 0 0] )
wall( size [0.1 5 1] pose [0 0 0 0] )
wall( size [0.1 5 1] pose [8 0 0 0] )
wall( size [3.5 0.1 1] pose [1.75 1.0 0 0] )
wall( size [4.05 0.1 1] pose [5.975 1.0 0 0] )
wall( size [8 0.1 1] pose [4 -2.5 0 0] )
"""  # a 0.95 m corridor (y 1.05..2.0) over a room (y -2.45..0.95), joined by a door from x 3.5 to 3.95


def test_the_wanderer_goes_through_a_narrow_door_into_a_new_room(tmp_path: Path) -> None:
    """The door is 0.45 m: 1.5 widths of the 0.3 m robot, too narrow for the explore and tour corridors."""
    run = closed_loop(tmp_path, 'simple_robot( pose [1.0 1.5 0 0] name "r" )', 150.0, seed=1,
                      walls=CORRIDOR_AND_ROOM)
    (summary,) = run.stats.summaries(["r"])
    assert summary["stall_events"] == 0 and summary["longest_stop_s"] < 2.0
    assert summary["coverage"] > 0.8  # the room is most of the free space: it has been inside


def test_a_doorway_it_is_wedged_in_front_of_is_given_up_while_it_backs_off() -> None:
    """Odometry that never changes: it stands still however it is commanded. After half a second it turns
    one way only; still stuck half a second later, it backs off and gives the doorway up (its far side
    counts as visited), rather than creeping at it for the passage's 30 s."""
    wanderer = Wanderer(seed=1)
    scan = scan_of_segments([*wall_with_gap(0.3, (0.2, 0.65), 4.0, vertical=True)])  # the jamb 4 cm ahead
    door = DoorPassage(np.array([0.3, 0.425]), np.array([1.0, 0.0]), until=30.0)
    wanderer.mode, wanderer._door = "door", door
    modes = []
    for step in range(1, 16):
        wanderer.decide(scan, step / 10, (0.0, 0.0, 0.0))
        modes.append(wanderer.mode)
    assert modes[:5] == ["door"] * 5 and modes[-1] != "door"
    assert wanderer.visits.visited_since(door.beyond(DOOR_BEYOND), 0.0).all()
