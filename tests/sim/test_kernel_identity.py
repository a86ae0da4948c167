"""Whole runs under the numba and the numpy kernels, and on 1 or 2 threads, are identical bit for bit.

Poses, odometry (with drawn ``odom_error``), stall flags, laser ranges (with noise) and intensities are
compared after every step, on worlds with heights, a transparent model, touching robots of every drive,
no robots, and every bundled world.
"""

from __future__ import annotations

import numpy as np
import pytest

from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.bundled import bundled_worlds, data_root
from stage_sim.worldfile.drive_names import DRIVE_NAMES
from stage_sim.worldfile.loader import load_world, load_world_text

WORLD = """
resolution 0.02
interval_sim 100
define wall model ( color "black" )
wall( size [8 0.04 1] pose [4 0 0 0] )
wall( size [8 0.04 1] pose [4 6 0 0] )
wall( size [0.04 6 1] pose [0 3 0 0] )
wall( size [0.04 6 1] pose [8 3 0 0] )
wall( name "low" size [1 0.3 0.08] pose [5 4.5 0 20] )
wall( name "glass" size [0.04 2 1] pose [6 2 0 0] ranger_return -1 )
wall( name "bright" size [0.5 0.5 1] pose [2 5 0 45] ranger_return 2 )
define laser ranger ( sensor( range [0 6] fov 270 samples 271 noise [0.0004 0.01 0.5] ) size [0.05 0.05 0.05] )
define bot position ( size [0.4 0.3 0.2] localization "odom" laser( pose [0.1 0 -0.1 0] ) )
"""


def crowd_world(seed: int) -> str:
    """Robots of every drive packed so that many touch (stalls), some low and invisible to others' lasers."""
    rng = np.random.default_rng(seed)
    lines = []
    for i in range(14):
        x, y = 1.0 + (i % 7) * 0.42, 1.0 + (i // 7) * 0.33
        drive = DRIVE_NAMES[i % len(DRIVE_NAMES)]
        extra = ' size [0.4 0.3 0.05]' if i % 5 == 4 else ""
        lines.append(f'bot( pose [{x:.3f} {y:.3f} 0 {rng.uniform(-20, 20):.1f}] drive "{drive}"{extra} )')
    lines.append('bot( pose [4.5 3.5 0 30] odom_error [0.1 0.05 0 0.2] )')
    lines.append('bot( pose [6.5 4 0 180] ranger_return 3 )')
    return WORLD + "\n".join(lines) + "\n"


def run(world, kernels: str, threads: int, steps: int, seed: int) -> list[tuple]:
    """Every step's poses, odometry, stalls, ranges and intensities under random commands."""
    sim = Simulation(world, seed=seed, kernels=kernels, threads=threads)
    assert sim.kernels == kernels
    commands = np.random.default_rng(seed).uniform([-0.4, -0.4, -1.5], [0.8, 0.4, 1.5], (steps, len(sim.robots), 3))
    frames = []
    for step in range(steps):
        for i, command in enumerate(commands[step]):
            sim.set_velocity(i, *command)
        sim.step()
        scans = [(s.ranges.tobytes(), s.intensities.tobytes()) for robot in sim.scans for s in robot]
        frames.append((sim.true_poses.tobytes(), sim.odometry_poses.tobytes(), sim.stalled.tobytes(), scans))
    return frames


@pytest.mark.parametrize("seed", [0, 1])
def test_crowd_of_every_drive_is_identical_under_both_kernels(seed):
    world = load_world_text(crowd_world(seed), "crowd.world")
    reference = run(world, "numpy", 1, 25, seed)
    assert run(world, "numba", 1, 25, seed) == reference
    sim = Simulation(world, seed=seed, kernels="numpy")
    assert len(sim.robots) == 16


def test_same_seed_same_run_on_one_and_two_threads():
    world = load_world_text(crowd_world(5), "crowd.world")
    assert run(world, "numba", 2, 20, 5) == run(world, "numba", 1, 20, 5)


def test_stalls_and_touching_robots_happen_in_the_crowd():
    sim = Simulation(load_world_text(crowd_world(0), "crowd.world"), seed=0)
    for i in range(len(sim.robots)):
        sim.set_velocity(i, 0.8, 0.0, 0.0)
    for _ in range(10):
        sim.step()
    assert sim.stalled.sum() >= 3


def test_world_without_robots_runs_under_both_kernels():
    for kernels in ("numpy", "numba"):
        sim = Simulation(load_world_text(WORLD, "empty.world"), seed=0, kernels=kernels)
        sim.step()
        assert sim.true_poses.shape == (0, 3) and sim.scans == []


@pytest.mark.parametrize("name", sorted(bundled_worlds()))
def test_every_bundled_world_is_identical_under_both_kernels(name):
    world = load_world(data_root() / "worlds" / name)
    assert run(world, "numba", 1, 5, 3) == run(world, "numpy", 1, 5, 3)


def test_a_thousand_robot_crowd_is_identical_under_both_kernels():
    rows = [f"bot( pose [{0.3 + (i % 40) * 0.19:.2f} {0.3 + (i // 40) * 0.23:.2f} 0 {(i * 37) % 360 - 180}] )"
            for i in range(1000)]
    # Packed closer than their size: a jammed crowd of overlapping, stalled robots.
    world = load_world_text(WORLD.replace("samples 271", "samples 9") + "\n".join(rows) + "\n", "thousand.world")
    numba_run = run(world, "numba", 2, 2, 9)
    assert numba_run == run(world, "numpy", 1, 2, 9)


SPREAD = """
resolution 0.05
interval_sim 100
define wall model ( color "black" )
wall( size [16 0.1 1] pose [8 0 0 0] )
wall( size [16 0.1 1] pose [8 16 0 0] )
wall( size [0.1 16 1] pose [0 8 0 0] )
wall( size [0.1 16 1] pose [16 8 0 0] )
define laser ranger ( sensor( range [0 5] fov 240 samples 61 ) size [0.05 0.05 0.05] )
define bot position ( size [0.4 0.3 0.2] localization "odom" laser( pose [0.1 0 -0.1 0] ) )
"""


def test_a_fused_step_that_grows_the_robot_layer_casts_as_the_reference(monkeypatch):
    """Robots leaving a huddle for every side come to need more of the robot layer's tiles than it held: the
    fused step grows it and casts again through the step's raster (``fused_kernels.sense_again``), as the
    reference casts."""
    from stage_sim.sim import fused_kernels

    rows = [f"bot( pose [{8 + np.cos(a):.3f} {8 + np.sin(a):.3f} 0 {np.degrees(a):.1f}] )"
            for a in np.linspace(0, 2 * np.pi, 10, endpoint=False)]
    world = load_world_text(SPREAD + "\n".join(rows) + "\n", "spread.world")
    regrown = []
    sense_again = fused_kernels.sense_again
    monkeypatch.setattr(fused_kernels, "sense_again", lambda *args: regrown.append(1) or sense_again(*args))
    frames = {}
    for kernels in ("numba", "numpy"):
        sim = Simulation(world, seed=4, kernels=kernels, threads=1)
        for i in range(len(sim.robots)):
            sim.set_velocity(i, 0.8, 0.0, 0.1)
        frames[kernels] = []
        for _ in range(80):
            sim.step()
            ranges = np.concatenate([s.ranges for robot in sim.scans for s in robot])
            frames[kernels].append((sim.true_poses.tobytes(), sim.stalled.tobytes(), ranges.tobytes()))
    assert regrown
    assert frames["numba"] == frames["numpy"]
