"""The compiled step arithmetic gives the numpy reference's arrays bit for bit, edge values included (the goal's
bearing as the agent sees it: a float32)."""

from __future__ import annotations

import copy
import math
from types import SimpleNamespace

import numpy as np
import pytest

from stage_sim.envs.spaces import (
    TAIL,
    ActionMap,
    ObservationBuilder,
    ObservationLayout,
    first_laser_ranges,
    goal_polar,
)
from stage_sim.envs.task import (
    RewardConfig,
    command_agents,
    compiled_command_agents,
    compiled_finish_step,
    finish_step,
)
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world_text

AGENTS = 5
ROBOTS = 7
BEAMS = 16
BOUNDS = np.array([[0.0, 1.0, 0, 0, 0, 0, -math.pi / 2, math.pi / 2]] * 4 + [[-0.5, 2.0, 0, 0, 0, 0, -1.0, 0.5]])


class Commandable:
    """``Simulation.set_velocities`` on a namespace's commands and stamps."""

    def __init__(self, state: SimpleNamespace) -> None:
        self.state = state

    def set_velocities(self, robots: np.ndarray, commands: np.ndarray) -> None:
        from stage_sim.sim.simulation import Simulation

        Simulation.set_velocities(self.state, robots, commands)  # type: ignore[arg-type]


def same(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal bit for bit (NaN equals NaN, −0.0 differs from 0.0)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("discrete", [False, True])
def test_commands_match_the_reference(discrete: bool) -> None:
    rng = np.random.default_rng(0)
    action_map = ActionMap(BOUNDS, discrete)
    for _ in range(200):
        if discrete:
            actions = rng.integers(0, action_map.table.shape[1], AGENTS)
        else:
            actions = rng.uniform(-3, 3, (AGENTS, 2)).astype(rng.choice([np.float32, np.float64]))
            actions.flat[rng.integers(0, actions.size, 3)] = rng.choice([-0.0, 0.0, np.nan, 1.0, -1.0], 3)
        active = rng.random(AGENTS) < 0.7
        rows = rng.permutation(ROBOTS)[:AGENTS]
        now = int(rng.integers(0, 10**9))
        mine, theirs = (SimpleNamespace(commands=np.full((ROBOTS, 3), 7.0), last_command_us=np.full(ROBOTS, -1),
                                        sim_time_us=now) for _ in range(2))
        compiled_command_agents(mine, rows, action_map, actions, active)
        command_agents(Commandable(theirs), rows, action_map, actions, active)
        assert same(mine.commands, theirs.commands) and same(mine.last_command_us, theirs.last_command_us)


def test_observations_rewards_and_ends_match_the_reference() -> None:
    rng = np.random.default_rng(1)
    layout = ObservationLayout(3, BEAMS, 4.0, math.pi, 12.0)
    action_map = ActionMap(BOUNDS, False)
    spaces = [layout.space(b) for b in BOUNDS]
    agents = np.array([0, 2, 3, 5, 6])
    reference = ObservationBuilder(layout, list(agents), spaces)
    compiled = copy.deepcopy(reference)
    reward = RewardConfig(progress=1.3, arrival=7.0, collision=-2.5, time=0.01, goal_tolerance=0.4)
    before = rng.uniform(0, 3, AGENTS)
    active = np.ones(AGENTS, dtype=bool)
    for step in range(300):
        scans = [[SimpleNamespace(ranges=rng.choice(
            [rng.uniform(0, 5), 0.0, -0.0, 4.0, np.nan, 3.9999998], BEAMS).astype(np.float32))] for _ in range(7)]
        velocities = rng.choice([0.0, -0.0, 0.3, 5.0, -2.0, np.nan], (7, 3))
        poses = rng.uniform(-5, 5, (7, 3))
        poses[:, 2] = rng.uniform(-4, 4, 7)
        sim = SimpleNamespace(scans=scans, measured_beams=None, velocities=velocities, stalled=rng.random(7) < 0.2,
                              true_poses=poses)
        goals = poses[agents, :2] + rng.choice([rng.uniform(-3, 3), 0.4, 0.0, 20.0], (AGENTS, 2))
        if step % 50 == 0:
            active[:] = True
        mine_active, their_active = active.copy(), active.copy()
        at_limit = step % 7 == 0
        mine = compiled_finish_step(compiled, reward, sim, agents, goals, before, mine_active, at_limit)
        theirs = finish_step(reference, reward, sim, agents, goals, before, their_active, at_limit)
        for field in ("observations", "rewards", "terminated", "truncated", "arrived", "collided", "distance",
                      "active"):
            assert same(getattr(mine, field), getattr(theirs, field)), (step, field)
        assert same(mine_active, their_active) and same(compiled.history, reference.history)
        assert mine.observations.shape == (AGENTS, layout.size) and TAIL == 4
        active, before = mine_active, theirs.distance
    assert action_map.table.shape[1] == 15


def test_the_goal_bearing_an_agent_sees_is_numpys() -> None:
    """The compiled bearing (libm's atan2) and numpy's (SVML on AVX-512) may differ in a float64's last bit; as
    the float32 the observation holds they agree, over 300,000 random poses and goals."""
    rng = np.random.default_rng(2)
    count = 300_000
    poses = np.column_stack([rng.uniform(-15, 15, (count, 2)), rng.uniform(-math.pi, math.pi, count)])
    goals = rng.uniform(-15, 15, (count, 2))
    agents = np.arange(count)
    layout = ObservationLayout(1, 1, 4.0, math.pi, 100.0)
    bounds = np.array([[-1e9, 1e9, 0, 0, 0, 0, -1e9, 1e9]] * count)
    spaces = [layout.space(bounds[0])] * count
    observer = ObservationBuilder(layout, list(agents), spaces)
    sim = SimpleNamespace(scans=[[SimpleNamespace(ranges=np.ones(1, dtype=np.float32))]] * count, measured_beams=None,
                          velocities=np.zeros((count, 3)), stalled=np.zeros(count, dtype=bool), true_poses=poses)
    result = compiled_finish_step(observer, RewardConfig(), sim, agents, goals, np.zeros(count),
                                  np.ones(count, dtype=bool), False)
    distance, bearing = goal_polar(poses, goals)
    assert same(result.distance, distance)
    assert same(result.observations[:, 2], bearing.astype(np.float32))


def test_the_ranges_an_env_observes_are_its_robots_first_lasers_latest_scans() -> None:
    """Read straight from the last cast's beams when it measured every ranger, from the scans when a slower
    ranger (here robot 1's first laser) was not due: the same values either way, for any robots in any
    order."""
    text = """
resolution 0.02
interval_sim 100
model( name "box" size [10 10 1] pose [5 5 0 0] boundary 1 )
model( name "pillar" size [0.5 0.5 1] pose [6 4 0 0] )
define laser ranger ( sensor( range [0 6] fov 180 samples 61 ) size [0.05 0.05 0.05] )
define bot position ( size [0.4 0.3 0.2] drive "diff" laser( pose [0.1 0 -0.1 0] ) )
define slow_bot position ( size [0.4 0.3 0.2] drive "diff" laser( pose [0.1 0 -0.1 0] update_interval 300 )
                           laser( pose [-0.1 0 -0.1 180] ) )
bot( pose [2 5 0 0] )
slow_bot( pose [7 7 0 90] )
bot( pose [4 2 0 45] )
"""
    sim = Simulation(load_world_text(text, "three.world"), seed=4, kernels="numba")
    paths = set()
    for step in range(9):
        sim.set_velocity(step % 3, 0.3, 0.0, 0.2)
        sim.step()
        paths.add(sim.measured_beams.due is None)
        for robots in ([0], [2, 0], [1], [1, 2, 0]):
            expected = np.stack([sim.scans[robot][0].ranges for robot in robots])
            assert same(first_laser_ranges(sim, np.array(robots)), expected), (step, robots)
    assert paths == {True, False}  # both ways were read


@pytest.mark.parametrize(("discrete", "robots"), [(False, 1), (True, 1), (False, 3)])
def test_a_step_in_one_call_is_the_step_part_by_part(discrete: bool, robots: int,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """A task's step in one compiled call (``Simulation.step_with``) gives every array that commanding, stepping
    and scoring one after the other give, bit for bit, over episodes; with several robots also the steps whose
    robot layer grew, whose call's cast was made again after it."""
    from stage_sim.envs.scenarios import Scenario, ScenarioOptions
    from stage_sim.envs.task import NavigationTask, TaskConfig
    from stage_sim.envs.worlds import RobotBody

    monkeypatch.setenv("STAGE_SIM_KERNELS", "numba")
    options = ScenarioOptions(scenario="obstacles", n_robots=robots, n_obstacles=6, arena_size=6.0,
                              body=RobotBody(laser_samples=24))
    tasks = [NavigationTask(Scenario(options), TaskConfig(max_steps=40, discrete=discrete)) for _ in range(2)]
    calls = {"one": 0, "grown": 0}
    step_with = Simulation.step_with

    def counted_step_with(sim: Simulation, kernel: object, arguments: tuple) -> bool:
        held = step_with(sim, kernel, arguments)
        calls["one" if held else "grown"] += 1
        return held

    monkeypatch.setattr(Simulation, "step_with", counted_step_with)
    rng = np.random.default_rng(3)
    fields = ("observations", "rewards", "terminated", "truncated", "arrived", "collided", "distance", "active")
    for episode in range(6):
        first = [task.reset(np.random.default_rng(episode)) for task in tasks]
        assert same(*first)
        while tasks[0].active.any():
            size = (robots,) if discrete else (robots, 2)
            actions = rng.integers(0, 15, size) if discrete else rng.uniform(-1, 2, size).astype(np.float32)
            one = tasks[0].step(actions)
            one = {name: np.copy(getattr(one, name)) for name in fields}  # the task's arrays, written again next step
            with monkeypatch.context() as parts:
                parts.setattr(Simulation, "fused_next", lambda sim: False)
                apart = tasks[1].step(actions)
            for name in fields:
                assert same(one[name], getattr(apart, name)), (episode, name)
        assert same(tasks[0].sim.true_poses, tasks[1].sim.true_poses)
    assert calls["one"] > 100
    assert calls["grown"] > 0 or robots == 1, calls
