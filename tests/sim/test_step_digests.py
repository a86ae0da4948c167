"""Whole runs replay bit for bit as they were recorded before the step lost its Python glue.

``tests/data/sim/step_digests.json`` holds, per case and kernels, a SHA-256 of everything a step leaves
behind (true poses, odometry, velocities, stall flags, sim time, every ranger's latest ranges, intensities
and stamp) after every step, and of the random generator's state at the end, recorded with the code that
stepped through the kernels one numpy call at a time. The cases cover the benchmark's lone robot and ten
robots, noise on range and angle, drawn odom errors, every drive, robots that touch and stall, two rangers
at different update intervals, the watchdog, resets and poses set between steps. Any change to how a step
is computed must leave these digests as they are. To record them anew (only for a change meant to alter
runs): ``python tests/sim/test_step_digests.py``.
"""

from __future__ import annotations

import hashlib
import json
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text

REPO = Path(__file__).resolve().parents[2]
RECORDED = REPO / "tests" / "data" / "sim" / "step_digests.json"
Commander = Callable[[Simulation, int], None]
"""Gives the robots their commands before a step (the step's index)."""

ROOMS = """
resolution 0.02
interval_sim {interval}
define floorplan model ( color "SlateGray" boundary 1 obstacle_return 1 )
floorplan( size [27.05 21.65 1.0] pose [13.525 10.825 0 0] bitmap "{bitmap}" )
define laser ranger ( sensor( range [0.0 5.6] fov 240.0 samples 240 ) size [0.06 0.06 0.06] )
define bot position ( size [0.4 0.3 0.2] drive "diff" localization "odom" odom_error [0.03 0.03 0 0.05]
                      laser( pose [0.23 0 -0.15 0] ) )
"""
# benchmarks/simulate.py's world_text(10, 240, 240.0, 5.6, 1): its first robot is the one-robot benchmark's
TEN_POSES = ["20.900 4.700 0 -85.8", "25.100 18.500 0 -72.5", "15.500 4.100 0 113.1", "13.100 8.300 0 -146.9",
             "25.700 14.900 0 36.0", "19.100 16.700 0 82.3", "10.100 13.100 0 -112.4", "17.300 16.100 0 -160.1",
             "22.700 16.100 0 -81.0", "21.500 6.500 0 56.7"]

# Three robots with a fast front laser and a slow, noisy back one; interval_sim 50 ms, so that the front one
# scans every second step and the back one every third.
TWO_RANGERS = """
resolution 0.02
interval_sim 50
define floorplan model ( color "SlateGray" boundary 1 obstacle_return 1 )
floorplan( size [27.05 21.65 1.0] pose [13.525 10.825 0 0] bitmap "{bitmap}" )
define front ranger ( sensor( range [0.0 5.6] fov 240.0 samples 90 ) size [0.06 0.06 0.06] update_interval 100 )
define back ranger ( sensor( range [0.1 3.0] fov 90.0 samples 31 noise [0.0004 0.02 0.8] ) size [0.06 0.06 0.06]
                     update_interval 150 )
define bot position ( size [0.4 0.3 0.2] front( pose [0.2 0 -0.1 0] ) back( pose [-0.2 0 -0.1 180] ) )
bot( pose [11.1 9.2 0 90] drive "omni" localization "odom" )
bot( pose [11.6 9.2 0 -90] drive "car" wheelbase 0.3 )
bot( pose [4.0 4.0 0 0] drive "diff" localization "odom" odom_error [0.05 0.02 0 0.1] ranger_return 2 )
"""

# One robot in a small room with a noisy laser, driven into the walls (stalls).
LONE = """
resolution 0.02
interval_sim 100
define wall model ( color "black" )
wall( size [3 0.04 1] pose [1.5 0 0 0] )
wall( size [3 0.04 1] pose [1.5 2 0 0] )
wall( size [0.04 2 1] pose [0 1 0 0] )
wall( size [0.04 2 1] pose [3 1 0 0] )
define laser ranger ( sensor( range [0 4] fov 360 samples 361 noise [0.001 0.02 0.3] ) size [0.05 0.05 0.05] )
position( pose [1 1 0 30] size [0.4 0.3 0.2] drive "omni" localization "odom" laser( pose [0.1 0 -0.1 0] ) )
"""


def circles() -> Commander:
    """The benchmark's command: every robot drives a circle."""

    def command(sim: Simulation, step: int) -> None:
        if step == 0:
            for i in range(len(sim.robots)):
                sim.set_velocity(i, 0.3, 0.0, 0.5)

    return command


def random_commands(seed: int, low=(-0.4, -0.4, -1.5), high=(0.8, 0.4, 1.5)) -> Commander:
    """A new random command for every robot at every step (a fresh sequence for every run)."""
    rng = np.random.default_rng(seed)

    def command(sim: Simulation, step: int) -> None:
        for i, velocity in enumerate(rng.uniform(low, high, (len(sim.robots), 3))):
            sim.set_velocity(i, *velocity)

    return command


def interrupted() -> Commander:
    """Commands now and then (the watchdog stops robots in between), a reset, poses set, batched commands."""
    return _interrupt


def _interrupt(sim: Simulation, step: int) -> None:
    rng = np.random.default_rng(step)
    if step % 7 < 3:
        sim.set_velocity(step % 3, *rng.uniform([-0.2, -0.3, -1.0], [0.6, 0.3, 1.0]))
    if step % 11 == 0:
        sim.set_velocities(np.array([0, 2]), rng.uniform(-0.5, 0.5, (2, 3)))
    if step == 120:
        sim.reset_positions()
    if step == 200:
        sim.set_pose(2, 4.5, 4.2, 0.7)
    if step == 240:
        sim.set_pose(0, 11.3, 9.2, -3.0)  # into the car robot's reach: they touch


def crowd(seed: int) -> str:
    from tests.sim.test_kernel_identity import crowd_world

    return crowd_world(seed)


def quiet_crowd(seed: int) -> str:
    """The crowd without noise and without its low robots: every robot in one height band, every ray at one
    height (a world the fused step takes)."""
    return crowd(seed).replace(" noise [0.0004 0.01 0.5]", "").replace(" size [0.4 0.3 0.05]", "")


@dataclass(frozen=True)
class Case:
    """A recorded run: its world, the simulation's options, its commands and its steps per kernels (fewer on
    the numpy reference, whose ray walk is slow)."""

    world: Callable[[], str]
    commands: Callable[[], Commander]  #: made anew for every run
    steps: dict[str, int]
    options: dict = field(default_factory=dict)


ONE = f"bot( pose [{TEN_POSES[0]}] )\n"
CASES = {
    "one_robot": Case(lambda: ROOMS + ONE, circles, {"numba": 500, "numpy": 60}),
    "ten_robots": Case(lambda: ROOMS + "".join(f"bot( pose [{pose}] )\n" for pose in TEN_POSES), circles,
                       {"numba": 300, "numpy": 30}),
    "one_robot_random": Case(lambda: ROOMS + ONE, lambda: random_commands(3), {"numba": 300, "numpy": 60}),
    "noisy_crowd": Case(lambda: crowd(0), lambda: random_commands(0), {"numba": 150, "numpy": 40}),
    "quiet_crowd": Case(lambda: quiet_crowd(1), lambda: random_commands(1), {"numba": 150, "numpy": 40}),
    "two_rangers": Case(lambda: TWO_RANGERS, interrupted, {"numba": 300, "numpy": 300}, {"watchdog_timeout": 0.3}),
    "two_quiet_rangers": Case(lambda: TWO_RANGERS.replace(" noise [0.0004 0.02 0.8]", ""), interrupted,
                              {"numba": 300, "numpy": 120}, {"watchdog_timeout": 0.3}),
    "lone_noisy": Case(lambda: LONE, lambda: random_commands(7, (-0.5, -0.5, -2.0), (1.0, 0.5, 2.0)),
                       {"numba": 300, "numpy": 150}),
}


def trace(case: Case, kernels: str) -> str:
    """The SHA-256 of a run of ``case`` on ``kernels``."""
    command = case.commands()
    world = load_world_text(case.world().format(bitmap=REPO / "maps" / "rooms.png", interval=100), "case.world")
    sim = Simulation(world, seed=11, kernels=kernels, threads=1, **case.options)
    digest = hashlib.sha256()

    def add(*values: object) -> None:
        for value in values:
            array = np.ascontiguousarray(value)
            digest.update(f"{array.dtype}{array.shape}".encode())
            digest.update(array.tobytes())

    for step in range(case.steps[kernels]):
        command(sim, step)
        sim.step()
        add(sim.true_poses, sim.odometry_poses, sim.velocities, sim.stalled, sim.true_velocities, sim.sim_time_us)
        for scans in sim.scans:
            for scan in scans:
                add(scan.ranges, scan.intensities, scan.stamp)
    digest.update(json.dumps(sim.rng.bit_generator.state, sort_keys=True).encode())
    return digest.hexdigest()


@pytest.mark.parametrize("kernels", ["numba", "numpy"])
@pytest.mark.parametrize("case", sorted(CASES))
def test_runs_replay_as_recorded(case: str, kernels: str) -> None:
    recorded = json.loads(RECORDED.read_text())
    assert trace(CASES[case], kernels) == recorded[case][str(CASES[case].steps[kernels])]


if __name__ == "__main__":
    RECORDED.parent.mkdir(parents=True, exist_ok=True)
    RECORDED.write_text(json.dumps({name: {str(steps): trace(case, kernels) for kernels, steps in case.steps.items()}
                                    for name, case in CASES.items()}, indent=1) + "\n")
    sys.exit(0)
