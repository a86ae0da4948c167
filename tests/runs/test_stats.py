"""The launch scripts' run summary, judged on scripted motions: distance, stall events, stops (dithering in
place included) and coverage of the free space reachable from the start."""

from __future__ import annotations

from pathlib import Path

import pytest

from stage_sim.runs.stats import RunStats
from stage_sim.sim.simulation import Simulation

WORLD = """
resolution 0.02
interval_sim 100
define wall model ( color "black" obstacle_return 1 ranger_return 1 )
define box position ( size [0.4 0.3 0.2] drive "omni" localization "gps" odom_error [0 0 0 0] )
wall( size [6 0.1 1] pose [3 0 0 0] )
wall( size [6 0.1 1] pose [3 4 0 0] )
wall( size [0.1 4 1] pose [0 2 0 0] )
wall( size [0.1 4 1] pose [6 2 0 0] )
box( pose [1 2 0 0] name "r" )
"""


def drive(tmp_path: Path, commands: list[tuple[float, float, float]]) -> dict:
    """Apply one command per 0.1 s step and return the robot's summary."""
    path = tmp_path / "stats.world"
    path.write_text(WORLD)
    sim = Simulation.from_world(path, seed=1, watchdog_timeout=0.0)
    stats = RunStats(sim)
    for command in commands:
        sim.set_velocity(0, *command)
        sim.step()
        stats.update()
    (summary,) = stats.summaries(["r"])
    return summary


def test_cruising_counts_distance_and_no_stop(tmp_path: Path) -> None:
    summary = drive(tmp_path, [(0.5, 0.0, 0.0)] * 40)
    assert summary["sim_seconds"] == pytest.approx(4.0)
    assert summary["distance_m"] == pytest.approx(2.0, abs=1e-6)
    assert summary["longest_stop_s"] <= 0.1
    assert summary["stall_events"] == 0


def test_standing_still_and_dithering_both_count_as_stops(tmp_path: Path) -> None:
    still = drive(tmp_path, [(0.5, 0.0, 0.0)] * 5 + [(0.0, 0.0, 0.0)] * 30 + [(0.5, 0.0, 0.0)] * 5)
    assert still["longest_stop_s"] == pytest.approx(3.0, abs=0.11)
    # Alternating small turns in place never stand at zero velocity, yet the robot goes nowhere.
    dither = drive(tmp_path, [(0.0, 0.0, 0.2 * (-1) ** k) for k in range(50)])
    assert dither["longest_stop_s"] == pytest.approx(5.0, abs=0.11)


def test_turning_in_place_and_slow_driving_are_not_stops(tmp_path: Path) -> None:
    assert drive(tmp_path, [(0.0, 0.0, 1.2)] * 50)["longest_stop_s"] <= 0.1
    assert drive(tmp_path, [(0.1, 0.0, 0.0)] * 50)["longest_stop_s"] <= 0.5  # 5 cm every half second


def test_driving_into_a_wall_is_one_stall_event(tmp_path: Path) -> None:
    summary = drive(tmp_path, [(-0.5, 0.0, 0.0)] * 40)  # 0.75 m to the west wall
    assert summary["stall_events"] == 1
    assert summary["distance_m"] < 1.0


def test_coverage_is_the_free_space_within_a_metre_of_the_path(tmp_path: Path) -> None:
    standing = drive(tmp_path, [(0.0, 0.0, 0.0)])["coverage"]
    # A disc of 1 m radius in a 5.9 × 3.9 m room: about pi / 23 of it.
    assert standing == pytest.approx(3.1416 / (5.9 * 3.9), rel=0.15)
    across = drive(tmp_path, [(0.5, 0.0, 0.0)] * 80)["coverage"]  # x 1 → 5 along the middle
    assert across == pytest.approx((4.0 * 2.0 + 3.1416) / (5.9 * 3.9), rel=0.15)
