"""In-process sessions for the launch scripts: the simulator and one wanderer per robot in one executor.

One process and one executor spare the launch machinery and, with ``speedup <= 0``, allow *lockstep*: step
the world, then spin until every wanderer has answered that step's scan with a command the simulator has
received, however long that takes (a busy or frozen machine only slows the run down), so a seed gives the
same run every time; a late answer is reported once, and a controller that has gone ends the run with an
error instead of a silent step without it. With ``speedup > 0`` the
simulator paces its own steps (:class:`~stage_sim.runs.pacing.Pacer`, as every entry point). Either way
:class:`~stage_sim.runs.stats.RunStats` samples the ground truth after every step and gives the JSON
summaries printed at exit.
"""

from __future__ import annotations

import argparse
import json
import sys
import threading
import time

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions

from stage_sim.bags.errors import BagError
from stage_sim.cli.arguments import add_duration_argument, add_seed_argument, add_speedup_argument
from stage_sim.interface.names import numbered
from stage_sim.interface.topics import CMD_VEL, ODOM, SCAN
from stage_sim.ros.bag_recording import add_bag_arguments, bag_recording
from stage_sim.ros.domain import use_private_domain
from stage_sim.ros.recording import add_record_arguments, recording
from stage_sim.ros.stageros import StageRos
from stage_sim.ros.view import add_view_options, viewing
from stage_sim.ros.wander import Wander
from stage_sim.runs.driver import wanderer_seed
from stage_sim.runs.interrupts import stop_requests
from stage_sim.runs.stats import RunStats
from stage_sim.worldfile.errors import WorldError

LATE_ANSWER_S = 5.0  # wall seconds of waiting for a lockstep answer before saying which robots are late
CONNECT_TIMEOUT_S = 10.0  # wall seconds for the in-process publishers and subscriptions to match


class ControllerGone(RuntimeError):
    """A lockstep session waits for a controller that no longer publishes its robot's commands."""


class WanderSession:
    """A simulator and a wanderer per robot (namespaced like the simulator's topics), in one executor, until
    the world's ``quit_time`` or ``duration`` sim seconds, whichever comes first. ``speedup`` None: the world's."""

    def __init__(self, world: str, speedup: float | None, seed: int | None, duration: float | None = None,
                 context: Context | None = None, recording: bool = False) -> None:
        """``recording``: a bag will record the simulator (which then leaves a core to its writer)."""
        self.stage = StageRos(world, speedup=speedup, seed=seed, autostep=False, duration=duration, context=context,
                              recording=recording)
        sim = self.stage.sim
        self.wanderers = []
        for index, (robot, names) in enumerate(zip(sim.robots, self.stage.names, strict=True)):
            remap = (["--ros-args", "-r", f"{SCAN.name}:={numbered(SCAN.name, len(robot.rangers))[0]}"]
                     if robot.rangers else None)
            overrides = [Parameter("holonomic", value=robot.drive.holonomic)]
            if seed is not None:
                overrides.append(Parameter("seed", value=wanderer_seed(seed, index)))
            self.wanderers.append(Wander(
                f"wander_{index}", namespace=names.label or None, context=context, cli_args=remap,
                parameter_overrides=overrides))
        self.controller_names = [w.get_name() for w in self.wanderers]  # kept for messages after a node has gone
        self.executor = SingleThreadedExecutor(context=context)
        for node in (self.stage, *self.wanderers):
            self.executor.add_node(node)
        self.stats = RunStats(sim)
        self.stage.add_step_listener(self.stats.update)

    def run(self, stop: threading.Event | None = None) -> None:
        """Step until the run's end or until ``stop`` is set (Ctrl-C)."""
        stop = stop or threading.Event()
        self._connect()
        stage = self.stage
        lockstep = stage.pacer.speedup <= 0
        if not lockstep:
            stage.start_stepping()
        while not stage.finished and not stop.is_set():
            if lockstep and not stage.pacer.paused:
                stage.step_once()
                self._await_answers(stop)
            else:
                self.executor.spin_once(timeout_sec=0.1)

    def summaries(self) -> list[dict]:
        """The per-robot JSON summaries, named after the robots' models."""
        return self.stats.summaries()

    def close(self) -> None:
        """Stop the robots and destroy every node."""
        for node in (*self.wanderers, self.stage):
            self.executor.remove_node(node)
            node.destroy_node()
        self.executor.shutdown(timeout_sec=1.0)

    def _connect(self) -> None:
        """Spin until every scan, odometry and command topic has matched (discovery, even in-process)."""
        publishers = self.stage.publishers_by_name
        watched = [[publishers[name] for name in (*ODOM.names_on(names), *SCAN.names_on(names)[:1])]
                   for names in self.stage.names]
        deadline = time.monotonic() + CONNECT_TIMEOUT_S
        while time.monotonic() < deadline and not all(
            w.publisher.get_subscription_count() and all(p.get_subscription_count() for p in watched[i])
            for i, w in enumerate(self.wanderers)
        ):
            self.executor.spin_once(timeout_sec=0.01)

    def _await_answers(self, stop: threading.Event) -> None:
        """Lockstep: spin until each robot that got a scan this step has had its command accepted, or ``stop``.

        Never steps on without an answer: says once which robots are late after LATE_ANSWER_S, and raises
        ControllerGone when a late robot's ``cmd_vel`` has no publisher left."""
        stage, sim = self.stage, self.stage.sim
        waiting = [i for i in range(len(self.wanderers)) if any(s.stamp == sim.sim_time for s in sim.scans[i])]
        commands = [names.topic(CMD_VEL.name) for names in stage.names]
        started, warned = time.monotonic(), False
        while not stop.is_set():
            late = [i for i in waiting if sim.last_command_us[i] != sim.sim_time_us]
            if not late:
                return
            self.executor.spin_once(timeout_sec=0.01)
            if time.monotonic() - started < LATE_ANSWER_S:
                continue
            gone = [i for i in late if stage.count_publishers(commands[i]) == 0]
            if gone:
                raise ControllerGone(f"lockstep: nothing publishes {', '.join(commands[i] for i in gone)} any more "
                                     f"(controller {', '.join(self.controller_names[i] for i in gone)})")
            if not warned:
                warned = True
                stage.get_logger().warning(
                    f"lockstep: the step to sim time {sim.sim_time:g} s has waited {LATE_ANSWER_S:g} s for the "
                    f"commands of {', '.join(commands[i] for i in late)} (nodes "
                    f"{', '.join(self.controller_names[i] for i in late)}); still waiting")


def parse_args(argv: list[str], prog: str, default_world: str, description: str) -> argparse.Namespace:
    """The launch scripts' common options."""
    parser = argparse.ArgumentParser(prog=prog, description=description)
    parser.add_argument("world", nargs="?", default=default_world,
                        help=f"a .world file or a bundled world's name (default {default_world})")
    add_speedup_argument(parser)
    add_duration_argument(parser)
    add_seed_argument(parser)
    add_record_arguments(parser)
    add_bag_arguments(parser)
    add_view_options(parser)
    return parser.parse_args(argv)


def wander_main(argv: list[str], prog: str, default_world: str, description: str) -> int:
    """Run a wander session (on a private DDS domain unless ROS_DOMAIN_ID is set); print one JSON summary per robot
    at the end (also after Ctrl-C)."""
    args = parse_args(argv, prog, default_world, description)
    use_private_domain(prog)
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    session = None
    try:
        with stop_requests() as stop:
            session = WanderSession(args.world, args.speedup, args.seed, args.duration, recording=bool(args.bag))
            with (recording(session.stage, args, prog), bag_recording(session.stage, args, prog) as recorder,
                  viewing(session.stage, args)):
                session.run(stop)
            for summary in session.summaries():
                print(json.dumps(summary), flush=True)
        return 0 if recorder is None or recorder.summary.complete else 1
    except (WorldError, FileNotFoundError, ValueError, BagError) as error:
        print(f"{prog}: {error}", file=sys.stderr)
        return 2
    except ControllerGone as error:
        print(f"{prog}: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 0
    finally:
        if session is not None:
            session.close()
        rclpy.try_shutdown()
