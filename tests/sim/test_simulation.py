"""The Simulation core on small synthetic worlds with hand-computed expectations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.description import WorldDescription
from stage_sim.worldfile.loader import load_world_text

# A 10 m × 10 m room of 2 cm walls; robot bodies 0.4 × 0.3 × 0.2 m; lasers 0.1 m ahead of the centre at
# height 0.2 − 0.1 + 0.01 (half the default sensor height) = 0.11 m, low enough to see other robots. The lasers
# reach 10 m: Stage's walk loses up to a step per empty region it jumps over, so a wall 7.88 m ahead is not
# reliably within reach of an 8 m laser (sensing/stage_walk.py).
ROOM = """
resolution 0.02
interval_sim 100
define wall model ( color "black" )
wall( name "south" size [10 0.02 1] pose [5 0 0 0] )
wall( name "north" size [10 0.02 1] pose [5 10 0 0] )
wall( name "west" size [0.02 10 1] pose [0 5 0 0] )
wall( name "east" size [0.02 10 1] pose [10 5 0 0] )
define laser ranger ( sensor( range [0 10] fov 180 samples 181 ) size [0.05 0.05 0.05] )
define bot position ( size [0.4 0.3 0.2] drive "{drive}" {extra} laser( pose [0.1 0 -0.1 0] ) )
"""


def world(robots: str, drive: str = "diff", extra: str = "", more: str = "") -> WorldDescription:
    text = ROOM.format(drive=drive, extra=extra) + more + robots
    return load_world_text(text, "test.world")


def sim_of(robots: str, seed: int | None = 0, **kwargs) -> Simulation:
    return Simulation(world(robots, **kwargs), seed=seed)


def test_diff_step_through_the_simulation() -> None:
    sim = sim_of('bot( pose [2 2 0 0] )')
    sim.set_velocity(0, 0.5, 0.3, 0.1)
    sim.step()
    assert sim.sim_time == pytest.approx(0.1)
    assert sim.true_poses[0] == pytest.approx([2.05, 2.0, 0.01])
    assert sim.velocities[0] == pytest.approx([0.5, 0.0, 0.1])


def test_omni_and_car_drives() -> None:
    omni = sim_of('bot( pose [2 2 0 90] )', drive="omni")
    omni.set_velocity(0, 0.0, 0.4, 0.0)
    omni.step()
    assert omni.true_poses[0] == pytest.approx([1.96, 2.0, math.pi / 2])
    car = sim_of('bot( pose [2 2 0 0] )', drive="car", extra="wheelbase 0.5")
    car.set_velocity(0, 0.8, 0.0, 0.3)
    car.step()
    assert car.true_poses[0] == pytest.approx([2 + 0.08 * math.cos(0.3), 2.0, 0.08 * math.sin(0.3) / 0.5])


def test_commands_are_clamped_to_default_velocity_bounds() -> None:
    sim = sim_of('bot( pose [2 2 0 0] )')
    sim.set_velocity(0, 3.0, 0.0, 9.0)
    sim.step()
    assert sim.true_poses[0] == pytest.approx([2.1, 2.0, math.pi / 20])


def test_odometry_with_literal_odom_error() -> None:
    sim = sim_of('bot( pose [2 2 0 0] )', extra='localization "odom" odom_error [0.1 0.0 0.0 0.0]')
    assert sim.odometry_poses[0] == pytest.approx([0.0, 0.0, 0.0])
    sim.set_velocity(0, 0.5, 0.0, 0.0)
    for _ in range(4):
        sim.step()
    assert sim.true_poses[0] == pytest.approx([2.2, 2.0, 0.0])
    assert sim.odometry_poses[0] == pytest.approx([0.22, 0.0, 0.0])


def test_gps_odometry_is_the_true_pose() -> None:
    sim = sim_of('bot( pose [2 2 0 30] )')
    sim.set_velocity(0, 0.5, 0.0, 0.5)
    for _ in range(5):
        sim.step()
    assert np.array_equal(sim.odometry_poses, sim.true_poses)


def test_localization_origin_sets_the_odometry_frame() -> None:
    extra = 'localization "odom" odom_error [0 0 0 0] localization_origin [1 1 0 0]'
    sim = sim_of('bot( pose [2 3 0 0] )', extra=extra)
    assert sim.odometry_poses[0] == pytest.approx([1.0, 2.0, 0.0])


def test_drawn_odom_error_depends_on_the_seed_only() -> None:
    robots = 'bot( pose [2 2 0 0] ) bot( pose [4 4 0 0] )'
    a = sim_of(robots, seed=1, extra='localization "odom"')
    b = sim_of(robots, seed=1, extra='localization "odom"')
    c = sim_of(robots, seed=2, extra='localization "odom"')
    assert np.array_equal(a.odom_errors, b.odom_errors)
    assert not np.array_equal(a.odom_errors, c.odom_errors)
    assert not np.array_equal(a.odom_errors[0], a.odom_errors[1])


def test_stall_against_a_wall_undoes_the_move_and_odometry_runs_on() -> None:
    sim = sim_of('bot( pose [9.5 5 0 0] )', extra='localization "odom" odom_error [0 0 0 0]')
    sim.set_velocity(0, 1.0, 0.0, 0.0)
    for _ in range(10):
        sim.step()
    assert sim.stalled[0]
    # body front at x + 0.2 must stay short of the wall's first cell (x = 9.98)
    assert sim.true_poses[0][0] + 0.2 < 9.98
    assert sim.true_poses[0][0] >= 9.7 - 1e-9
    assert sim.odometry_poses[0][0] == pytest.approx(1.0)  # 10 steps × 0.1 m, wheels spinning
    sim.set_velocity(0, -0.5, 0.0, 0.0)
    sim.step()
    assert not sim.stalled[0]


def test_stall_against_another_robot() -> None:
    sim = sim_of('bot( pose [2 2 0 0] ) bot( pose [2.7 2 0 0] )')
    sim.set_velocity(0, 1.0, 0.0, 0.0)
    for _ in range(5):
        sim.step()
    assert sim.stalled[0] and not sim.stalled[1]
    gap = sim.true_poses[1][0] - sim.true_poses[0][0]
    assert 0.4 <= gap < 0.55
    assert sim.true_poses[1] == pytest.approx([2.7, 2.0, 0.0])


def test_reset_positions_restores_start_and_clears_state() -> None:
    sim = sim_of('bot( pose [9.5 5 0 0] )', extra='localization "odom" odom_error [0 0 0 0]')
    sim.set_velocity(0, 1.0, 0.0, 0.3)
    for _ in range(8):
        sim.step()
    time = sim.sim_time
    sim.reset_positions()
    assert sim.true_poses[0] == pytest.approx([9.5, 5.0, 0.0])
    assert sim.odometry_poses[0] == pytest.approx([0.0, 0.0, 0.0])
    assert not sim.stalled[0]
    assert np.all(sim.velocities == 0) and np.all(sim.commands == 0)
    assert sim.sim_time == time
    sim.step()
    assert sim.true_poses[0] == pytest.approx([9.5, 5.0, 0.0])


def test_set_pose_moves_a_stalled_robot_clear_and_its_laser_sees_from_there() -> None:
    sim = sim_of('bot( pose [9.5 5 0 0] )', extra='localization "odom" odom_error [0 0 0 0]')
    sim.set_velocity(0, 1.0, 0.0, 0.0)
    for _ in range(5):
        sim.step()
    assert sim.stalled[0]
    odometry = sim.odometry_poses[0].copy()
    sim.set_pose(0, 5.0, 5.0, 3 * math.pi / 2)
    assert sim.true_poses[0] == pytest.approx([5.0, 5.0, -math.pi / 2])
    assert not sim.stalled[0]
    assert sim.odometry_poses[0] == pytest.approx(odometry)  # dragging is not wheel motion
    sim.set_velocity(0, 0.0, 0.0, 0.0)
    sim.step()
    centre = sim.scans[0][0].ranges[90]  # straight ahead: south wall, from the laser 0.1 m ahead
    assert centre == pytest.approx(5.0 - 0.1 - 0.02 / 2, abs=0.02)


def test_set_pose_rejects_unknown_robots_and_non_finite_poses() -> None:
    sim = sim_of('bot( pose [2 2 0 0] )')
    with pytest.raises(IndexError):
        sim.set_pose(1, 1.0, 1.0, 0.0)
    with pytest.raises(ValueError):
        sim.set_pose(0, math.nan, 1.0, 0.0)
    assert sim.true_poses[0] == pytest.approx([2.0, 2.0, 0.0])


def test_watchdog_stops_a_robot_without_commands() -> None:
    sim = Simulation(world('bot( pose [2 2 0 0] )'), seed=0, watchdog_timeout=0.2)
    sim.set_velocity(0, 0.5, 0.0, 0.0)
    sim.step()
    assert sim.velocities[0][0] == pytest.approx(0.5)
    sim.step()
    assert sim.velocities[0][0] == 0.0
    x = sim.true_poses[0][0]
    sim.step()
    assert sim.true_poses[0][0] == x


def test_watchdog_stops_each_silent_robot_at_its_own_time_also_after_a_reset() -> None:
    """The watchdog looks at the robots only once the oldest command can have timed out: a robot driven at
    every step is never stopped, one left alone is stopped on time, a command written straight into
    ``commands`` of a silent robot is dropped at the next step, and a reset starts the clocks again."""
    sim = Simulation(world('bot( pose [2 2 0 0] ) bot( pose [5 5 0 0] )'), seed=0, watchdog_timeout=0.25)
    sim.set_velocities(np.array([0, 1]), np.array([[0.5, 0.0, 0.0], [0.4, 0.0, 0.0]]))
    moving = []
    for _ in range(6):
        sim.set_velocity(0, 0.5, 0.0, 0.0)
        sim.step()
        moving.append(sim.velocities[:, 0].tolist())
    assert moving == [[0.5, 0.4], [0.5, 0.4], [0.5, 0.0], [0.5, 0.0], [0.5, 0.0], [0.5, 0.0]]
    sim.commands[1, 0] = 0.3  # not a command: the watchdog still counts robot 1 silent
    sim.set_velocity(0, 0.5, 0.0, 0.0)
    sim.step()
    assert sim.velocities[:, 0].tolist() == [0.5, 0.0]
    sim.reset()
    sim.set_velocities(np.array([0, 1]), np.array([[0.2, 0.0, 0.0], [0.1, 0.0, 0.0]]))
    after = []
    for _ in range(4):
        sim.step()
        after.append(sim.velocities[:, 0].tolist())
    assert after == [[0.2, 0.1], [0.2, 0.1], [0.0, 0.0], [0.0, 0.0]]


def test_set_velocities_commands_several_robots_as_set_velocity_does_each() -> None:
    robots = 'bot( pose [2 2 0 0] ) bot( pose [5 5 0 0] ) bot( pose [7 2 0 0] )'
    one_by_one, at_once = sim_of(robots), sim_of(robots)
    one_by_one.set_velocity(2, 0.3, 0.0, 0.2)
    one_by_one.set_velocity(0, 0.5, 0.0, -0.1)
    at_once.set_velocities(np.array([2, 0]), np.array([[0.3, 0.0, 0.2], [0.5, 0.0, -0.1]]))
    for _ in range(3):
        one_by_one.step()
        at_once.step()
    assert np.array_equal(one_by_one.true_poses, at_once.true_poses)
    assert at_once.true_poses[1].tolist() == [5.0, 5.0, 0.0]  # not commanded: stays


def test_scan_range_is_the_distance_to_the_first_wall_cell() -> None:
    sim = sim_of('bot( pose [2 5 0 0] )')
    scan = sim.scans[0][0]
    assert len(scan.ranges) == 181
    # laser at x = 2.1; the east wall spans [9.99, 10.01], so its first cell starts at x = 9.98
    assert scan.ranges[90] == pytest.approx(9.98 - 2.1)
    assert scan.ranges[90] == pytest.approx(7.88)
    assert scan.intensities[90] == pytest.approx(1.0)
    # straight left (beam 180, +90°) hits the north wall: first cell at y = 9.98
    assert scan.ranges[180] == pytest.approx(9.98 - 5.0, abs=1e-6)


def test_scans_follow_the_post_move_pose_and_update_interval() -> None:
    sim = sim_of('bot( pose [2 5 0 0] )', more="")
    sim.set_velocity(0, 0.5, 0.0, 0.0)
    sim.step()
    assert sim.scans[0][0].stamp == pytest.approx(0.1)
    assert sim.scans[0][0].ranges[90] == pytest.approx(7.83)
    slow = load_world_text(ROOM.replace("size [0.05 0.05 0.05] )", "size [0.05 0.05 0.05] update_interval 200 )")
                           .format(drive="diff", extra="") + 'bot( pose [2 5 0 0] )', "slow.world")
    sim = Simulation(slow, seed=0)
    stamps = []
    for _ in range(4):
        sim.step()
        stamps.append(round(sim.scans[0][0].stamp, 6))
    assert stamps == [0.0, 0.2, 0.2, 0.4]


def test_scans_read_late_are_the_scans_read_at_every_step() -> None:
    """A fused step's scans are made when first read: a reader who looks only now and then (after steps that
    cast every ranger, and after steps that cast one of them) gets what a reader at every step got."""
    two = ROOM.format(drive="diff", extra='laser( pose [-0.1 0 -0.1 180] update_interval 200 )')
    text = two + 'bot( pose [2 5 0 0] ) bot( pose [6 6 0 90] )'

    def scans(sim: Simulation) -> list[tuple]:
        return [(s.ranges.tobytes(), s.intensities.tobytes(), s.stamp) for robot in sim.scans for s in robot]

    eager, late = (Simulation(load_world_text(text, "two.world"), seed=2, kernels="numba") for _ in range(2))
    assert eager._fused is not None
    seen = []
    for step in range(12):
        for sim in (eager, late):
            sim.set_velocity(0, 0.3, 0.0, 0.2 * (-1) ** (step // 3))
            sim.step()
        seen.append(scans(eager))
        if step in (4, 7, 8, 11):
            assert scans(late) == seen[-1]
    assert {stamp for _, _, stamp in seen[-1]} == {1.2}
    assert {stamp for _, _, stamp in seen[-2]} == {1.0, 1.1}, "the slow laser's last scan is a step older"


def test_low_obstacles_are_invisible_to_high_lasers_and_transparent_ones_to_all() -> None:
    low = 'model( size [0.5 0.5 0.05] pose [5 5 0 0] )\n'
    sim = sim_of('bot( pose [2 5 0 0] )', more=low)
    # laser height 0.11 m > 0.05 m
    assert sim.scans[0][0].ranges[90] == pytest.approx(7.88)
    glass = 'model( size [0.5 0.5 1] pose [5 5 0 0] ranger_return -1 )\n'
    sim = sim_of('bot( pose [2 5 0 0] )', more=glass)
    assert sim.scans[0][0].ranges[90] == pytest.approx(7.88)
    wall = 'model( size [0.5 0.5 1] pose [5 5 0 0] ranger_return 3 )\n'
    sim = sim_of('bot( pose [2 5 0 0] )', more=wall)
    assert sim.scans[0][0].ranges[90] == pytest.approx(4.74 - 2.1)
    assert sim.scans[0][0].intensities[90] == pytest.approx(3.0)


def test_lasers_see_other_robots_but_not_their_own() -> None:
    sim = sim_of('bot( pose [2 5 0 0] ) bot( pose [4 5 0 180] )')
    # robot 1's body spans x ∈ [3.8, 4.2]: its outline cell starts at 3.8
    assert sim.scans[0][0].ranges[90] == pytest.approx(3.8 - 2.1, abs=0.021)
    # looking right (−90°) through its own body to the south wall's first cell [0, 0.02): Stage's walk reports
    # the 250 whole cells walked from y = 5 (the cell's far side), not the true ray's 4.98 m
    assert sim.scans[0][0].ranges[0] == pytest.approx(5.0)


def test_same_seed_same_everything_with_noise() -> None:
    noisy = ROOM.replace("samples 181 )", "samples 181 noise [0.0004 0.01 1] )")

    def run(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        sim = Simulation(load_world_text(noisy.format(drive="diff", extra='localization "odom"')
                                         + 'bot( pose [2 5 0 0] ) bot( pose [6 6 0 90] )', "n.world"), seed=seed)
        poses, odoms, scans = [], [], []
        for k in range(30):
            sim.set_velocity(0, 0.4, 0.0, 0.2 * math.sin(k / 5))
            sim.set_velocity(1, 0.3, 0.0, -0.1)
            sim.step()
            poses.append(sim.true_poses.copy())
            odoms.append(sim.odometry_poses.copy())
            scans.append(np.concatenate([s.ranges for r in sim.scans for s in r]))
        return np.array(poses), np.array(odoms), np.array(scans)

    a, b, c = run(5), run(5), run(6)
    for x, y in zip(a, b, strict=True):
        assert np.array_equal(x, y)
    assert not np.array_equal(a[1], c[1])
    assert not np.array_equal(a[2], c[2])


def test_reset_with_seed_restarts_time_and_random_draws() -> None:
    sim = sim_of('bot( pose [2 2 0 0] )', seed=3, extra='localization "odom"')
    errors = sim.odom_errors.copy()
    sim.set_velocity(0, 0.5, 0.0, 0.0)
    sim.step()
    sim.reset(seed=3)
    assert sim.sim_time == 0.0
    assert np.array_equal(sim.odom_errors, errors)
    assert sim.true_poses[0] == pytest.approx([2.0, 2.0, 0.0])


def test_a_robot_starting_inside_a_wall_is_reported() -> None:
    sim = sim_of('bot( pose [9.9 5 0 0] name "stuck" ) bot( pose [2 2 0 0] name "free" )')
    messages = [w.message for w in sim.warnings]
    assert any("'stuck' starts overlapping" in m for m in messages)
    assert not any("'free'" in m for m in messages)


def test_resets_cast_no_rays_and_the_next_step_scans_from_the_start_pose() -> None:
    sim = sim_of('bot( pose [2 5 0 0] )')
    sim.set_velocity(0, 1.0, 0.0, 0.0)
    for _ in range(5):
        sim.step()
    before = sim.scans[0][0]
    for _ in range(1000):
        sim.reset_positions()
    assert sim.scans[0][0] is before  # a storm of resets costs no ray casting
    sim.step()
    assert sim.scans[0][0].stamp == pytest.approx(sim.sim_time)
    assert sim.scans[0][0].ranges[90] == pytest.approx(7.88)


@pytest.mark.parametrize(("kernels", "noise"), [("numpy", ""), ("numba", ""), ("numba", "noise [0.0004 0.01 1]")])
def test_a_world_with_static_models_added_simulates_as_if_built_from_scratch(kernels: str, noise: str) -> None:
    # An episode's obstacles: the simulation reuses its robots, raster and beam tables and traces only the new
    # bodies (with the backend's tracer: the compiled one on numba), whatever the base world has done.
    robots = 'bot( pose [2 5 0 0] ) bot( pose [6 6 0 90] )'
    room = ROOM.replace("samples 181 )", f"samples 181 {noise} )")
    base = load_world_text(room.format(drive="diff", extra="") + robots, "test.world")
    boxes = load_world_text(room.format(drive="diff", extra="") + robots
                            + 'model( name "box" size [0.5 0.3 1] pose [4 5.2 0 30] )'
                            + 'model( name "low" size [0.4 0.4 0.05] pose [7 4 0 0] )', "test.world")
    extended = WorldDescription(base.path, base.settings, [*base.models, *boxes.models[-2:]])
    original = Simulation(base, seed=1, kernels=kernels)
    for _ in range(3):  # what its casts changed is not the new world's
        original.set_velocity(0, 0.5, 0.0, 0.2)
        original.step()
    built, fresh = original.with_static_models(extended, seed=4), Simulation(extended, seed=4, kernels=kernels)
    assert built.robots is original.robots and built.static.bodies[0] is original.static.bodies[0]  # reused
    assert built.static.shape == fresh.static.shape and built.static.origin_xy == fresh.static.origin_xy
    assert [b.name for b in built.static.bodies] == [b.name for b in fresh.static.bodies]
    for mine, theirs in zip(built.static.bodies, fresh.static.bodies, strict=True):
        assert np.array_equal(mine.outline, theirs.outline) and mine.z == theirs.z
    for sim in (built, fresh):
        for k in range(25):
            sim.set_velocity(0, 0.6, 0.0, 0.3 * math.sin(k / 4))
            sim.set_velocity(1, 0.4, 0.0, -0.2)
            sim.step()
    assert np.array_equal(built.true_poses, fresh.true_poses) and np.array_equal(built.stalled, fresh.stalled)
    assert all(np.array_equal(a[0].ranges, b[0].ranges) and np.array_equal(a[0].intensities, b[0].intensities)
               for a, b in zip(built.scans, fresh.scans, strict=True))
    assert built.description is extended and built.warnings == fresh.warnings


@pytest.mark.parametrize("kernels", ["numpy", "numba"])
def test_static_models_that_reach_past_the_grid_grow_it_as_a_world_built_from_scratch(kernels: str) -> None:
    # An episode's box drawn against a wall pokes out of the world's box: the grid grows on both sides (the old
    # outlines move onto it), and the simulation is still the base's robots over the new raster.
    robots = 'bot( pose [9 5 0 0] ) bot( pose [1 1 0 -135] )'
    base = world(robots)
    boxes = load_world_text(ROOM.format(drive="diff", extra="") + robots
                            + 'model( name "out_east" size [1 1 1] pose [10.2 5 0 45] )'
                            + 'model( name "out_south_west" size [0.6 0.6 1] pose [0 0 0 20] )', "test.world")
    extended = WorldDescription(base.path, base.settings, [*base.models, *boxes.models[-2:]])
    original = Simulation(base, seed=1, kernels=kernels)
    built, fresh = original.with_static_models(extended, seed=4), Simulation(extended, seed=4, kernels=kernels)
    assert built.robots is original.robots  # not built from scratch
    assert built.static.shape != original.static.shape
    assert built.static.shape == fresh.static.shape and built.static.origin_xy == fresh.static.origin_xy
    for mine, theirs in zip(built.static.bodies, fresh.static.bodies, strict=True):
        assert mine.name == theirs.name and np.array_equal(mine.outline, theirs.outline)
        assert np.array_equal(mine.cells, theirs.cells)
    for sim in (built, fresh):
        for _ in range(30):
            sim.set_velocity(0, 0.5, 0.0, 0.0)  # into the box that pokes through the east wall
            sim.set_velocity(1, 0.4, 0.0, 0.1)
            sim.step()
    assert built.stalled[0] and np.array_equal(built.true_poses, fresh.true_poses)
    assert np.array_equal(built.stalled, fresh.stalled)
    assert all(np.array_equal(a[0].ranges, b[0].ranges) and np.array_equal(a[0].intensities, b[0].intensities)
               for a, b in zip(built.scans, fresh.scans, strict=True))


@pytest.mark.parametrize("kernels", ["numpy", "numba"])
def test_simulations_of_the_same_world_share_its_static_parts_and_step_apart(kernels: str) -> None:
    # A vector env's worlds of one world file: each is its own simulation (poses, scans, robot layer), and the
    # raster, its tiles and the rays' casters are held once; each steps as a simulation built from scratch.
    robots = 'bot( pose [2 5 0 0] ) bot( pose [6 6 0 90] )'
    base = Simulation(world(robots), seed=1, kernels=kernels)
    twins = [base.with_static_models(base.description, seed=seed) for seed in (4, 5)]
    fresh = [Simulation(base.description, seed=seed, kernels=kernels) for seed in (4, 5)]
    casters = [{id(group.caster) for group in sim._sensing._groups} for sim in (base, *twins)]
    assert all(sim.static is base.static for sim in twins) and casters[1] == casters[2] == casters[0]
    assert twins[0]._sensing._groups[0].robots is not twins[1]._sensing._groups[0].robots
    for k in range(30):
        for sims, turn in ((twins, 0.3), (fresh, 0.3)):
            sims[0].set_velocity(0, 0.6, 0.0, turn * math.sin(k / 4))
            sims[1].set_velocity(1, 0.5, 0.0, -0.2)
            for sim in sims:
                sim.step()
    for twin, alone in zip(twins, fresh, strict=True):
        assert np.array_equal(twin.true_poses, alone.true_poses) and np.array_equal(twin.stalled, alone.stalled)
        assert np.array_equal(twin.odometry_poses, alone.odometry_poses)
        assert all(np.array_equal(a[0].ranges, b[0].ranges) and np.array_equal(a[0].intensities, b[0].intensities)
                   for a, b in zip(twin.scans, alone.scans, strict=True))
    assert not np.array_equal(twins[0].true_poses, twins[1].true_poses)


def test_a_world_that_is_not_this_one_plus_static_models_is_built_from_scratch() -> None:
    sim = sim_of('bot( pose [2 5 0 0] )')
    other = world('bot( pose [3 5 0 0] )')
    made = sim.with_static_models(other, seed=0)  # other objects (a robot elsewhere): nothing to share
    assert made.robots is not sim.robots
    assert made.static.shape == Simulation(other, seed=0).static.shape
    assert made.true_poses.tolist() == Simulation(other, seed=0).true_poses.tolist()




def test_a_step_with_a_callers_kernel_is_refused_unless_it_is_one_compiled_call() -> None:
    """``step_with`` makes only the steps ``fused_next`` announces; any other is refused before it starts."""
    from stage_sim.sim import fused_kernels

    robot = "bot( pose [2 2 0 0] )\n"
    for kernels, watchdog in (("numpy", 0.0), ("numba", 5.0)):
        sim = Simulation(world(robot), seed=0, watchdog_timeout=watchdog, kernels=kernels)
        assert not sim.fused_next()
        with pytest.raises(ValueError, match="fused_next"):
            sim.step_with(fused_kernels.commanded_step, ())
        assert sim.sim_time_us == 0
    sim = Simulation(world(robot), seed=0, kernels="numba")
    sim.set_velocity(0, 0.5, 0.0, 0.2)
    assert sim.fused_next()
    assert sim.step_with(fused_kernels.commanded_step, ())
    twin = Simulation(world(robot), seed=0, kernels="numba")
    twin.set_velocity(0, 0.5, 0.0, 0.2)
    twin.step()
    assert sim.true_poses.tobytes() == twin.true_poses.tobytes()
    assert sim.measured_beams.ranges.tobytes() == twin.measured_beams.ranges.tobytes()
