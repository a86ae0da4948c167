"""One chooser maps a kernels name to the code that runs, and both backends fill every role of the interface."""

from __future__ import annotations

import numpy as np
import pytest

from stage_sim.backend import KERNELS
from stage_sim.sensing.casters import RayCaster
from stage_sim.sensing.fast_caster import NumbaRayCaster
from stage_sim.sensing.raycast import GridRayCaster
from stage_sim.sim import compiled, returns
from stage_sim.sim.backends import Backend, Motion, ReferenceMotion, backend_for, no_fused_step
from stage_sim.sim.collision import CollisionChecker, Contact
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text

WORLD = """
define laser ranger ( sensor( range [0 2] fov 180 samples 9 ) )
define bot position ( size [0.4 0.3 0.2] laser( ) )
model( size [4 4 0.5] pose [0 0 0 0] boundary 1 )
bot( pose [0 0 0 0] )
bot( pose [1 0 0 0] )
"""


def _public_methods(protocol: type) -> set[str]:
    return {name for name, value in vars(protocol).items() if callable(value) and not name.startswith("_")}


def test_the_chooser_maps_each_name_to_its_implementations():
    numpy, numba = backend_for("numpy"), backend_for("numba")
    assert (numpy.name, numba.name) == ("numpy", "numba")
    assert (numpy.contact, numba.contact) == (CollisionChecker, compiled.CompiledCollisionChecker)
    assert isinstance(numpy.motion, ReferenceMotion) and isinstance(numba.motion, compiled.CompiledMotion)
    assert (numpy.hit_intensity, numba.hit_intensity) == (returns.hit_intensity, compiled.hit_intensity)
    assert (numpy.fused, numba.fused) == (no_fused_step, compiled.FusedStep.of)
    assert isinstance(numpy.caster(np.zeros((4, 4), dtype=bool), 0.1, (0.0, 0.0)), GridRayCaster)
    assert isinstance(numba.caster(np.zeros((4, 4), dtype=bool), 0.1, (0.0, 0.0)), NumbaRayCaster)
    assert backend_for("numba") is numba  # built once
    with pytest.raises(ValueError, match="kernels must be one of numba, numpy"):
        backend_for("fortran")


@pytest.mark.parametrize("kernels", KERNELS)
def test_every_backend_fills_every_role(kernels):
    backend = backend_for(kernels)
    assert isinstance(backend, Backend)
    caster = backend.caster(np.zeros((4, 4), dtype=bool), 0.1, (0.0, 0.0))
    assert isinstance(caster, RayCaster)
    for role, implementation in ((Contact, backend.contact), (Motion, type(backend.motion))):
        missing = {name for name in _public_methods(role) if not callable(getattr(implementation, name, None))}
        assert not missing, f"{implementation.__name__} lacks {missing}"


@pytest.mark.parametrize("kernels", KERNELS)
def test_a_simulation_runs_on_the_parts_its_kernels_name(kernels):
    sim = Simulation(load_world_text(WORLD, "two.world"), seed=0, kernels=kernels)
    backend = backend_for(kernels)
    assert type(sim._collision) is backend.contact
    assert sim._motion is backend.motion
    assert all(isinstance(group.caster, RayCaster) for group in sim._sensing._groups)
    sim.set_velocity(0, 0.3, 0.0, 0.2)
    sim.step()
    assert sim.scans[0][0].ranges.shape == (9,)


def _frames(sim: Simulation, steps: int, seed: int) -> list[tuple]:
    """Every step's state under random commands, a reset and a pose set on the way."""
    commands = np.random.default_rng(seed).uniform([-0.4, -0.4, -1.5], [0.8, 0.4, 1.5], (steps, len(sim.robots), 3))
    frames = []
    for step in range(steps):
        sim.set_velocities(np.arange(len(sim.robots)), commands[step])
        if step == steps // 3:
            sim.reset_positions()
        if step == steps // 2:
            sim.set_pose(0, *sim.start_poses[1])  # onto another robot: both stall until one backs away
        sim.step()
        scans = [(s.ranges.tobytes(), s.intensities.tobytes(), s.stamp) for robot in sim.scans for s in robot]
        frames.append((sim.true_poses.tobytes(), sim.odometry_poses.tobytes(), sim.stalled.tobytes(), scans))
    return frames


@pytest.mark.parametrize(("threads", "noisy"), [(1, False), (2, False), (1, True)])
def test_the_fused_step_gives_the_role_by_role_answers(threads, noisy):
    from tests.sim.test_step_digests import crowd

    text = crowd(2).replace(" size [0.4 0.3 0.05]", "").replace("samples 271", "samples 41")  # one height band,
    # few enough rays for one thread's cast
    world = load_world_text(text if noisy else text.replace(" noise [0.0004 0.01 0.5]", ""), "crowd.world")
    fused = Simulation(world, seed=4, kernels="numba", threads=threads)
    by_roles = Simulation(world, seed=4, kernels="numba", threads=threads)
    by_roles._fused = None
    assert fused._fused is not None
    assert _frames(fused, 30, 4) == _frames(by_roles, 30, 4)


def test_robots_in_several_height_bands_step_role_by_role():
    from tests.sim.test_step_digests import crowd

    assert Simulation(load_world_text(crowd(0), "crowd.world"), seed=0, kernels="numba")._fused is None
    assert Simulation(load_world_text(WORLD, "two.world"), seed=0, kernels="numba")._fused is not None


MIXED = """
resolution 0.02
interval_sim 100
define wall model ( color "black" )
wall( size [4 0.04 1] pose [2 0 0 0] )
wall( size [4 0.04 1] pose [2 3 0 0] )
wall( size [0.04 3 1] pose [0 1.5 0 0] )
wall( size [0.04 3 1] pose [4 1.5 0 0] )
define laser ranger ( sensor( range [0 3] fov 270 samples 61 noise [0.0 0.02 0.0] ) size [0.05 0.05 0.05] )
define bot position ( size [0.4 0.3 0.2] laser( pose [0.1 0 -0.1 0] ) )
bot( pose [1 1 0 0] localization "odom" )
position( pose [1.5 1 0 90] size [0.4 0.3 0.2] )
bot( pose [2 1 0 180] obstacle_return 0 drive "omni" )
bot( pose [2.5 2 0 45] ranger_return -1 drive "car" )
bot( pose [1.2 2.2 0 -30] laser( pose [-0.1 0 -0.1 180] ) )
"""
"""A robot without a laser, one no robot collides with, one no laser sees, gps and odom, three drives."""


def test_the_fused_step_on_a_mixed_world_gives_the_reference_answers():
    world = load_world_text(MIXED, "mixed.world")
    fused = Simulation(world, seed=3, kernels="numba")
    by_roles = Simulation(world, seed=3, kernels="numba")
    by_roles._fused = None
    assert fused._fused is not None
    reference = _frames(Simulation(world, seed=3, kernels="numpy"), 40, 3)
    assert _frames(fused, 40, 3) == reference
    assert _frames(by_roles, 40, 3) == reference


def _still_frames(sim: Simulation) -> list[tuple]:
    """Every step's state while the robots stand still, one is pushed against another (stalled), robots are set
    where they are and elsewhere, and all go back to their start."""
    frames = []
    for step in range(60):
        if step in (3, 6):  # moves for some steps, then stands still: one layer holds it where it was a step ago
            sim.set_velocity(4, 0.6 if step == 3 else 0.0, 0.0, 0.0)
        if step == 10:
            sim.set_velocity(0, 1.0, 0.0, 0.0)  # drives into the robot ahead of it and stalls there
        if step == 30:
            sim.set_pose(1, *sim.true_poses[1])  # where it is: the same cast
        if step == 40:
            sim.set_pose(1, 1.5, 1.5, 0.5)
        if step == 50:
            sim.reset_positions()
        sim.step()
        scans = [(s.ranges.tobytes(), s.intensities.tobytes(), s.stamp) for robot in sim.scans for s in robot]
        frames.append((sim.true_poses.tobytes(), sim.odometry_poses.tobytes(), sim.stalled.tobytes(), scans))
    return frames


@pytest.mark.parametrize("angle_noise", [False, True])
def test_robots_standing_still_are_not_cast_again_and_get_the_reference_answers(angle_noise):
    """A fused step whose robots are all where they were (parked, stalled) answers with the last cast and this
    step's range noise instead of walking every ray again; the answers stay the reference's. A direction noise
    changes every cast: nothing is kept."""
    text = MIXED.replace("noise [0.0 0.02 0.0]", "noise [0.0 0.02 0.5]") if angle_noise else MIXED
    world = load_world_text(text, "mixed.world")
    fused = Simulation(world, seed=5, kernels="numba")
    assert fused._fused is not None
    frames = _still_frames(fused)
    assert frames == _still_frames(Simulation(world, seed=5, kernels="numpy"))
    assert np.frombuffer(frames[25][2], dtype=bool)[0], "the pushing robot stalls"
    replayed = fused._fused.replayed_casts
    assert replayed == 0 if angle_noise else replayed >= 35
