"""stage_sim beside the 2D lidar simulators an RL user would also pick, on one scenario, one JSON line per case.

The scenario (issue #34): diff-drive robots of radius 0.2 m, each with a 512-beam 180° 4 m lidar, in a
30 × 30 m walled arena with 8 boxes (sides 0.3–1 m), dt 0.1 s, a uniformly random action (0–1 m/s,
±π/2 rad/s) for every robot at every step; 1, 10 and 100 robots. Simulators and the API measured:

* ``stage_sim env``: ``stage_sim/Navigate-v0`` (1 robot) or ``NavigateParallelEnv`` (10, 100), the
  obstacles scenario, whose boxes are drawn anew in every episode; episodes that end are reset (resets count
  in the time);
* ``stage_sim env, fixed boxes``: the same env on a world file holding the boxes the peers get (the
  ``"random"`` scenario: new starts and goals every episode, the boxes where they are), as navground's env
  keeps the boxes of its scenario from one episode to the next;
* ``stage_sim vector env`` (1-robot rows only): ``NavigateVectorEnv`` of 64 such one-robot worlds stepped
  together (its worlds' steps in one compiled call, autoresets counted in the time), every world's robot an
  agent: what an RL user running N copies of the one-robot env gets from stage_sim; ``stage_sim vector env,
  fixed boxes`` the same on the peers' boxes;
* ``stage_sim core``: the same world's ``Simulation.step`` (commands written, one step, no env), only that
  timed; the world is reset through the env (untimed) when the env would end the episode (every robot has
  collided, or the step limit), so that the core steps robots in open space as the env's do, not resting
  against a wall with short rays;
* ``stage_sim rays``: the floor under both, Stage's ray walk alone: the same core run, each step's lidars cast
  once more by the world's role-by-role sensing, and the rate counts only the seconds spent in that compiled
  ray walk (its calls timed one by one), so it says how fast any step that casts these lidars the way Stage
  does could be on this core;
* ``navground env`` / ``navground world``: navground 0.7 through navground-learning's Gymnasium env (1
  robot) or shared parallel env (10, 100), and its bare ``World`` (commands set, ``actuate``, every
  agent's lidar updated);
* ``irsim-x`` (C++ lidar) and ``ir-sim`` (pure Python): ``irsim.make`` of a YAML world, ``env.step``.

The peers run in venvs of their own (``.venv-peers/<peer>``, made by ``make bench-peers`` from
``benchmarks/peers/<peer>.lock``); a peer whose venv is missing is left out, so the stage_sim rows run
anywhere. Each measurement is its own process pinned to one core (``taskset -c --core``), and the
repetitions alternate between simulators (rep 1 of every case, then rep 2, …) so that load drifts hit all
alike. Per case: ``agent_steps_per_s`` counts every robot of every step (each robot's lidar is cast at every
step in all of them) and ``live_agent_steps_per_s`` only robots whose episode is running (the envs that end
episodes); min and max over ``--reps``. ``lidar_sees_robots`` is probed, not assumed: a robot 1 m straight
ahead of another must show in the middle beam of its scan.

    .venv/bin/python benchmarks/rl_peers.py [--robots 1 10 100] [--seconds 3] [--reps 3] [--core 0]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
ARENA = 30.0
BOXES = 8
BOX_SIDES = (0.3, 1.0)
RADIUS = 0.2
BEAMS, FOV, RANGE = 512, math.pi, 4.0
DT = 0.1
V_MAX, W_MAX = 1.0, math.pi / 2
#: Case → the venv (under --venvs) whose interpreter runs it; None: this interpreter (stage_sim's venv).
CASES: dict[str, str | None] = {
    "stage_sim env": None, "stage_sim env, fixed boxes": None, "stage_sim vector env": None,
    "stage_sim vector env, fixed boxes": None, "stage_sim core": None, "stage_sim rays": None,
    "navground env": "navground", "navground world": "navground",
    "irsim-x": "irsim-x", "ir-sim": "ir-sim",
}
#: Cases of one-robot worlds only (run in the 1-robot rows).
ONE_ROBOT_CASES = {"stage_sim vector env", "stage_sim vector env, fixed boxes"}
#: The worlds of the vector env case.
VECTOR_WORLDS = 64
#: The probe of ``lidar_sees_robots``: robot 1 a metre straight ahead of robot 0, nothing else around.
PROBE = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
#: Steps run before the clock starts (compiled kernels loaded, first scans, caches warm).
WARM_UP = 20
#: Random actions drawn per run (then taken again from the first).
ACTION_ROWS = 1000


# -- the scenario, the same numbers for every simulator ------------------------------------------------

def layout(robots: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Boxes (8, 5: x, y, side x, side y, yaw) and robot poses (robots, 3) in an arena centred on 0, robots
    clear of the boxes and of each other (rejection sampling from ``seed``)."""
    rng = np.random.default_rng(seed)
    half = ARENA / 2 - 1.0
    boxes = np.column_stack([rng.uniform(-half, half, (BOXES, 2)), rng.uniform(*BOX_SIDES, (BOXES, 2)),
                             rng.uniform(-math.pi, math.pi, BOXES)])
    poses: list[tuple[float, float, float]] = []
    while len(poses) < robots:
        x, y = rng.uniform(-half, half, 2)
        if (np.hypot(boxes[:, 0] - x, boxes[:, 1] - y).min() > 1.0
                and all(math.hypot(px - x, py - y) > 4 * RADIUS for px, py, _ in poses)):
            poses.append((x, y, rng.uniform(-math.pi, math.pi)))
    return boxes, np.array(poses)


def box_corners(box: np.ndarray) -> list[tuple[float, float]]:
    """The four corners of a box (x, y, side x, side y, yaw), counter-clockwise."""
    x, y, sx, sy, yaw = box
    c, s = math.cos(yaw), math.sin(yaw)
    return [(x + c * dx - s * dy, y + s * dx + c * dy)
            for dx, dy in ((-sx / 2, -sy / 2), (sx / 2, -sy / 2), (sx / 2, sy / 2), (-sx / 2, sy / 2))]


def actions(robots: int, steps: int, seed: int) -> np.ndarray:
    """Random (forward speed, turn rate) per step and robot, drawn before the clock starts."""
    rng = np.random.default_rng(seed + 1)
    return np.stack([rng.uniform(0, V_MAX, (steps, robots)), rng.uniform(-W_MAX, W_MAX, (steps, robots))], -1)


# -- one measurement per process ------------------------------------------------------------------------

class Runner:
    """One simulator at one size: ``step`` advances every robot once, returns how many were live."""

    sees_robots: bool
    agents: int  #: robots a step advances (an action row each)

    def step(self, action: np.ndarray) -> int:
        raise NotImplementedError

    def start_timing(self) -> None:
        """The warm-up is over: what :meth:`timed_seconds` counts starts now."""

    def timed_seconds(self, wall: float) -> float:
        """The seconds the rate counts of ``wall`` seconds of stepping: all of them, unless a runner times a
        part."""
        return wall


class EnvRunner(Runner):
    """A Gymnasium env (one robot; reset when its episode ends) or a PettingZoo parallel env (reset when no
    agent is left): ``step`` hands each live agent its row of the actions."""

    env: Any
    single: bool

    def step_env(self, rows: np.ndarray, row_of: Callable[[Any], int]) -> int:
        """One step with the actions ``rows`` (robot, 2) in the env's own units; agent → row by ``row_of``."""
        if self.single:
            _, _, terminated, truncated, _ = self.env.step(rows[0])
            if terminated or truncated:
                self.env.reset()
            return 1
        if not self.env.agents:
            self.env.reset()
        live = len(self.env.agents)
        self.env.step({agent: rows[row_of(agent)] for agent in self.env.agents})
        return live


#: The obstacles scenario as stage_sim's envs take it.
STAGE_OPTIONS = {"scenario": "obstacles", "n_obstacles": BOXES, "obstacle_size": BOX_SIDES, "arena_size": ARENA,
                 "resolution": 0.05}


@contextlib.contextmanager
def stage_options(fixed: bool, seed: int) -> Iterator[dict[str, Any]]:
    """The envs' keyword arguments: the obstacles scenario, or (``fixed``) the ``"random"`` scenario of a world
    file holding the arena and the boxes the peers get from ``seed``, for as long as the env is being built (it
    reads the file then)."""
    if not fixed:
        yield STAGE_OPTIONS
        return
    import tempfile

    from stage_sim.envs.worlds import arena_text, obstacles_text

    with tempfile.TemporaryDirectory() as folder:
        world = Path(folder) / "fixed_boxes.world"
        world.write_text(arena_text(ARENA, STAGE_OPTIONS["resolution"]) + obstacles_text(layout(0, seed)[0]))
        yield {"scenario": "random", "world": world}


class StageEnv(EnvRunner):
    fixed = False  #: the peers' boxes, which stay put, instead of new ones every episode

    def __init__(self, robots: int, seed: int) -> None:
        from stage_sim.envs import NavigateEnv, NavigateParallelEnv

        self.agents = robots
        self.single = robots == 1
        with stage_options(self.fixed, seed) as options:
            self.env = NavigateEnv(**options) if self.single else NavigateParallelEnv(n_robots=robots, **options)
        self.row_of = int if self.single else {name: k for k, name in enumerate(self.env.possible_agents)}.__getitem__
        self.env.reset(seed=seed)
        self.sees_robots = stage_sees_robots()

    def step(self, action: np.ndarray) -> int:
        return self.step_env(action.astype(np.float32), self.row_of)


class StageEnvFixed(StageEnv):
    fixed = True


class StageVectorEnv(Runner):
    """``NavigateVectorEnv`` of :data:`VECTOR_WORLDS` one-robot worlds (the obstacles scenario, next-step
    autoreset): a step advances every world, and the worlds reset by it are not live."""

    fixed = False

    def __init__(self, robots: int, seed: int) -> None:
        from stage_sim.envs import NavigateVectorEnv

        with stage_options(self.fixed, seed) as options:
            self.env = NavigateVectorEnv(VECTOR_WORLDS, **options)
        self.env.reset(seed=seed)
        self.agents = VECTOR_WORLDS
        self.sees_robots = stage_sees_robots()

    def step(self, action: np.ndarray) -> int:
        infos = self.env.step(action.astype(np.float32))[4]
        return int(infos["_arrived"].sum())  # the worlds that stepped (the others were reset)


class StageVectorEnvFixed(StageVectorEnv):
    fixed = True


class StageCore(StageEnv):
    """The env's world stepped by ``Simulation.step`` alone (commands written into its array, one step, only
    those timed), through the env's episodes: once every robot has collided or the env's step limit is reached,
    the env resets the world (not timed). Without that the robots soon rest against walls with their rays
    short, and the core would be timed on cheaper steps than the env takes."""

    def __init__(self, robots: int, seed: int) -> None:
        super().__init__(robots, seed)
        self.max_steps = self.env.task.config.max_steps
        self.timed = 0.0
        self.new_episode()

    def new_episode(self) -> None:
        """Take the world the env has just reset (the obstacles scenario makes a new one each episode)."""
        self.sim = self.env.task.sim
        self.ended = np.zeros(len(self.sim.robots), dtype=bool)
        self.episode_steps = 0

    def step(self, action: np.ndarray) -> int:
        start = time.perf_counter()
        self.sim.commands[:, 0] = action[:, 0]
        self.sim.commands[:, 2] = action[:, 1]
        self.sim.step()
        self.timed += time.perf_counter() - start
        self.after_step()
        self.ended |= self.sim.stalled
        self.episode_steps += 1
        if self.ended.all() or self.episode_steps >= self.max_steps:
            self.next_episode()
        return len(action)

    def next_episode(self) -> None:
        self.env.reset()
        self.new_episode()

    def after_step(self) -> None:
        """What a subclass measures of each step, before an episode's end may reset the world."""

    def start_timing(self) -> None:
        self.timed = 0.0

    def timed_seconds(self, wall: float) -> float:
        return self.timed


class StageRays(StageCore):
    """The core run, and after each step every lidar cast again by the role-by-role sensing of the same world
    (the fused step walks inside one compiled call), its compiled ray walk's calls timed: the rate of the rays
    alone."""

    def __init__(self, robots: int, seed: int) -> None:
        from stage_sim.sensing import traversal

        self.ray_seconds = 0.0
        self.kernels = {name: getattr(traversal, name) for name in ("cast_serial", "cast_parallel")}
        super().__init__(robots, seed)

    @contextlib.contextmanager
    def bare_kernels(self) -> Iterator[None]:
        """The ray walk's own kernels while worlds are built (building checks their signatures), then timed."""
        from stage_sim.sensing import traversal

        for name, kernel in self.kernels.items():
            setattr(traversal, name, kernel)
        yield
        for name, kernel in self.kernels.items():
            setattr(traversal, name, self._timed(kernel))

    def new_episode(self) -> None:
        with self.bare_kernels():
            super().new_episode()
            _, self.sensing = self.sim.build_parts("numba")

    def next_episode(self) -> None:
        with self.bare_kernels():
            super().next_episode()

    def _timed(self, kernel: Callable[..., Any]) -> Callable[..., Any]:
        def timed(*args: Any) -> Any:
            start = time.perf_counter()
            try:
                return kernel(*args)
            finally:
                self.ray_seconds += time.perf_counter() - start
        return timed

    def after_step(self) -> None:
        self.sensing.invalidate()  # every lidar due, as in the core's steps
        self.sensing.sense(self.sim.true_poses, self.sim.sim_time)

    def start_timing(self) -> None:
        self.ray_seconds = 0.0

    def timed_seconds(self, wall: float) -> float:
        return self.ray_seconds


def stage_sees_robots() -> bool:
    from stage_sim.envs import NavigateParallelEnv

    env = NavigateParallelEnv(scenario="random", n_robots=2, arena_size=ARENA)
    env.reset(seed=0)
    sim = env.task.sim
    sim.set_pose(0, 0.0, 0.0, 0.0)
    sim.set_pose(1, 1.0, 0.0, 0.0)
    sim.step()
    return bool(sim.scans[0][0].ranges[BEAMS // 2] < 0.9)


def navground_yaml(boxes: np.ndarray, poses: np.ndarray, scenario: bool = False) -> str:
    """A navground world (or, ``scenario``, a scenario of one-agent groups): arena and boxes as walls."""
    half = ARENA / 2
    square = [(-half, -half), (half, -half), (half, half), (-half, half)]
    walls = [(a, b) for outline in [square, *map(box_corners, boxes)]
             for a, b in zip(outline, outline[1:] + outline[:1], strict=True)]
    lines = ["walls:"] + [f"  - line: [[{a[0]}, {a[1]}], [{b[0]}, {b[1]}]]" for a, b in walls]
    lines.append("groups:" if scenario else "agents:")
    for x, y, yaw in poses:
        lines += ["  - type: ''", *(["    number: 1"] if scenario else []), f"    radius: {RADIUS}",
                  f"    position: [{x}, {y}]", f"    orientation: {yaw}", f"    control_period: {DT}",
                  "    behavior: {type: Dummy}",
                  f"    kinematics: {{type: 2WDiff, max_speed: {V_MAX}, wheel_axis: {4 * RADIUS}}}",
                  f"    state_estimation: {NAVGROUND_LIDAR}"]
    return "\n".join(lines) + "\n"


NAVGROUND_LIDAR = (f"{{type: Lidar, name: lidar, range: {RANGE}, start_angle: {-FOV / 2}, field_of_view: {FOV}, "
                   f"resolution: {BEAMS}}}")


class NavgroundWorld(Runner):
    """The bare world: each agent's command set, ``World.actuate``, each agent's lidar updated into its state."""

    def __init__(self, robots: int, seed: int) -> None:
        from navground import core, sim

        self.core = core
        self.agents = robots
        self.world = sim.load_world(navground_yaml(*layout(robots, seed)))
        self.states = []
        for agent in self.world.agents:
            state = core.SensingState()
            agent.state_estimation.prepare_state(state)
            self.states.append(state)
        self.sees_robots = navground_sees_robots()

    def step(self, action: np.ndarray) -> int:
        core = self.core
        for agent, (v, w) in zip(self.world.agents, action, strict=True):
            agent.last_cmd = core.Twist2((float(v), 0.0), float(w), frame=core.Frame.relative)
        self.world.actuate(DT)
        for agent, state in zip(self.world.agents, self.states, strict=True):
            agent.state_estimation.update(agent, self.world, state)
        return len(action)


def navground_sees_robots() -> bool:
    from navground import core, sim

    world = sim.load_world(navground_yaml(np.empty((0, 5)), PROBE))
    agent = world.agents[0]
    state = core.SensingState()
    agent.state_estimation.prepare_state(state)
    agent.state_estimation.update(agent, world, state)
    return bool(np.asarray(agent.state_estimation.read_ranges(state))[BEAMS // 2] < 0.9)


class NavgroundEnv(EnvRunner):
    """navground-learning's envs: the Gymnasium env (1 robot) or the shared parallel env (every robot an agent),
    actions in [-1, 1] scaled by the env to the robot's limits."""

    def __init__(self, robots: int, seed: int) -> None:
        import gymnasium
        import navground.learning.env  # noqa: F401  (registers "navground")
        from navground import sim
        from navground.learning import ControlActionConfig, DefaultObservationConfig

        self.agents = robots
        from navground.learning.parallel_env import shared_parallel_env

        scenario = sim.load_scenario(navground_yaml(*layout(robots, seed), scenario=True))
        options = {"scenario": scenario, "sensor": NAVGROUND_LIDAR, "time_step": DT, "max_duration": 50.0,
                   "terminate_if_idle": False,
                   "action": ControlActionConfig(use_acceleration_action=False),
                   "observation": DefaultObservationConfig(include_target_direction=False,
                                                           include_target_distance=False)}
        self.single = robots == 1
        self.env = gymnasium.make("navground", **options) if self.single else shared_parallel_env(**options)
        self.env.reset(seed=seed)
        self.sees_robots = navground_sees_robots()

    def step(self, action: np.ndarray) -> int:
        scaled = np.column_stack([2 * action[:, 0] / V_MAX - 1, action[:, 1] / W_MAX]).astype(np.float32)
        return self.step_env(scaled, int)  # its agents are their indices


def irsim_yaml(boxes: np.ndarray, poses: np.ndarray) -> str:
    """An ir-sim world: its frame runs from (0, 0) to (width, height), so everything moves by half the arena."""
    shift = ARENA / 2
    states = [[x + shift, y + shift, yaw] for x, y, yaw in poses]
    robot = (f"  - number: {len(poses)}\n    distribution: {{name: manual}}\n    state: {json.dumps(states)}\n"
             f"    kinematics: {{name: diff}}\n    shape: {{name: circle, radius: {RADIUS}}}\n"
             f"    vel_min: [0, {-W_MAX}]\n    vel_max: [{V_MAX}, {W_MAX}]\n    sensors:\n"
             f"      - {{name: lidar2d, range_min: 0, range_max: {RANGE}, angle_range: {FOV}, number: {BEAMS}}}\n")
    obstacles = "".join(
        f"  - number: 1\n    distribution: {{name: manual}}\n    state: [[{x + shift}, {y + shift}, {yaw}]]\n"
        f"    shape: [{{name: rectangle, length: {sx}, width: {sy}}}]\n" for x, y, sx, sy, yaw in boxes)
    return (f"world:\n  height: {ARENA}\n  width: {ARENA}\n  step_time: {DT}\n  sample_time: {DT}\n"
            f"  collision_mode: stop\nrobot:\n{robot}" + (f"obstacle:\n{obstacles}" if obstacles else ""))


class IrSim(Runner):
    """ir-sim or irsim-x (both install the ``irsim`` module): ``env.step`` with every robot's action."""

    def __init__(self, robots: int, seed: int) -> None:
        self.env = irsim_env(irsim_yaml(*layout(robots, seed)), f"rl_peers_{robots}_{seed}")
        self.agents = robots
        self.ids = list(range(robots))
        self.sees_robots = irsim_sees_robots()

    def step(self, action: np.ndarray) -> int:
        self.env.step(list(action.reshape(-1, 2, 1)), action_id=self.ids)
        return len(action)


def irsim_env(text: str, name: str) -> Any:
    import tempfile

    import irsim

    path = Path(tempfile.mkdtemp()) / f"{name}.yaml"
    path.write_text(text)
    return irsim.make(str(path), display=False, disable_all_plot=True, log_level="WARNING")


def irsim_sees_robots() -> bool:
    env = irsim_env(irsim_yaml(np.empty((0, 5)), PROBE), "rl_peers_probe")
    env.step([np.zeros((2, 1)), np.zeros((2, 1))], action_id=[0, 1])
    return bool(np.asarray(env.robot_list[0].get_lidar_scan()["ranges"])[BEAMS // 2] < 0.9)


RUNNERS: dict[str, type[Runner]] = {
    "stage_sim env": StageEnv, "stage_sim env, fixed boxes": StageEnvFixed, "stage_sim vector env": StageVectorEnv,
    "stage_sim vector env, fixed boxes": StageVectorEnvFixed, "stage_sim core": StageCore,
    "stage_sim rays": StageRays, "navground env": NavgroundEnv,
    "navground world": NavgroundWorld, "irsim-x": IrSim, "ir-sim": IrSim,
}


def measure(case: str, robots: int, seconds: float, seed: int) -> dict[str, Any]:
    """Steps for ``seconds`` of wall time after the warm-up (building the world is not timed), the random
    actions drawn beforehand and taken in turn."""
    runner = RUNNERS[case](robots, seed)
    commands = actions(runner.agents, ACTION_ROWS, seed)
    for action in commands[:WARM_UP]:
        runner.step(action)
    steps = live = 0
    runner.start_timing()
    start = time.perf_counter()
    while (elapsed := time.perf_counter() - start) < seconds:
        live += runner.step(commands[steps % ACTION_ROWS])
        steps += 1
    timed = runner.timed_seconds(elapsed)
    return {"steps": steps, "agent_steps_per_s": runner.agents * steps / timed, "live_agent_steps_per_s": live / timed,
            "lidar_sees_robots": runner.sees_robots}


# -- the driver: alternating processes, pinned ------------------------------------------------------------

def interpreter(case: str, venvs: Path) -> Path | None:
    """The Python that runs ``case``, or None when its peer's venv is not there."""
    venv = CASES[case]
    if venv is None:
        return Path(sys.executable)
    python = venvs / venv / "bin" / "python"
    return python if python.is_file() else None


def run_case(python: Path, case: str, robots: int, seconds: float, seed: int, core: int | None) -> dict[str, Any]:
    command = [str(python), __file__, "--worker", case, "--robots", str(robots), "--seconds", str(seconds),
               "--seed", str(seed)]
    if core is not None and shutil.which("taskset"):
        command = ["taskset", "-c", str(core), *command]
    # stage_sim's compiled kernels from the first step (else it steps on numpy while numba loads).
    env = {**os.environ, "PYTHONPATH": str(REPO), "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg",
           "STAGE_SIM_KERNELS": "numba"}
    done = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{case} with {robots} robots failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[1, 10, 100])
    parser.add_argument("--seconds", type=float, default=3.0, help="timed wall seconds per run")
    parser.add_argument("--reps", type=int, default=3, help="runs per case, alternating between simulators")
    parser.add_argument("--core", type=int, default=0, help="the core every run is pinned to (-1: no pinning)")
    parser.add_argument("--venvs", type=Path, default=REPO / ".venv-peers", help="where the peers' venvs are")
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES), metavar="CASE")
    parser.add_argument("--worker", choices=list(CASES), help=argparse.SUPPRESS)
    parser.add_argument("--seed", type=int, default=0, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        print(json.dumps(measure(args.worker, args.robots[0], args.seconds, args.seed)), flush=True)
        return 0
    pythons = {case: interpreter(case, args.venvs) for case in args.cases}
    for case, python in pythons.items():
        if python is None:
            print(f"rl_peers: {case} left out: no {args.venvs / str(CASES[case])} (make bench-peers)", file=sys.stderr)
    cases = [case for case, python in pythons.items() if python is not None]
    core = None if args.core < 0 else args.core
    for robots in args.robots:
        runs: dict[str, list[dict[str, Any]]] = {case: [] for case in cases
                                                  if robots == 1 or case not in ONE_ROBOT_CASES}
        for rep in range(args.reps):
            for case in runs:
                runs[case].append(run_case(pythons[case], case, robots, args.seconds, rep, core))
        for case in runs:
            line: dict[str, Any] = {"bench": "rl_peers", "simulator": case, "robots": robots, "reps": args.reps,
                                    "steps": min(run["steps"] for run in runs[case])}
            for key in ("agent_steps_per_s", "live_agent_steps_per_s"):
                values = [run[key] for run in runs[case]]
                line[key] = f"{min(values):,.0f}–{max(values):,.0f}"
                line[f"{key}_min"], line[f"{key}_max"] = round(min(values), 1), round(max(values), 1)
            line["lidar_sees_robots"] = runs[case][0]["lidar_sees_robots"]
            print(json.dumps(line), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
