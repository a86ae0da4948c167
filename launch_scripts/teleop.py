#!/usr/bin/env python3
"""Simulator + keyboard teleop (the course's ``teleop.launch``), in one process, without the launch package.

``python launch_scripts/teleop.py [WORLD] [--speedup X] [--duration S] [--seed N] [--record OUT]`` runs the
world (default ``rooms.world``) and drives its first robot with teleop_twist_keyboard's keys typed on this
terminal (``u i o / j k l / m , .``; Ctrl-C quits) until Ctrl-C, ``--duration`` sim seconds or the world's
``quit_time``.
"""

import os
import sys
import threading
from pathlib import Path

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions

from stage_sim.ros.domain import use_private_domain
from stage_sim.ros.recording import recording
from stage_sim.ros.session import parse_args
from stage_sim.ros.stageros import StageRos
from stage_sim.ros.teleop import KeyReader, TeleopTwistKeyboard
from stage_sim.ros.view import viewing
from stage_sim.runs.interrupts import sigterm_interrupts
from stage_sim.worldfile.errors import WorldError


def main(argv: list[str]) -> int:
    """Spin the simulator in a thread while the teleop reads the keyboard; 0 on Ctrl-C or at the duration."""
    args = parse_args(argv, "teleop.py", "rooms.world", __doc__.splitlines()[0])
    use_private_domain("teleop.py")
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    nodes = []
    executor = SingleThreadedExecutor()
    done = threading.Event()

    def spin() -> None:
        """Step the world until told to stop, the duration or the world's quit_time; then end the teleop too."""
        while not done.is_set() and not stage.finished:
            executor.spin_once(timeout_sec=0.1)
        rclpy.try_shutdown()  # ends the teleop's key loop within its poll interval

    try:
        with sigterm_interrupts():
            stage = StageRos(args.world, speedup=args.speedup, seed=args.seed, duration=args.duration)
            nodes.append(stage)
            namespace = stage.names[0].label if stage.names else ""
            teleop = TeleopTwistKeyboard(namespace=namespace or None)
            nodes.append(teleop)
            for node in nodes:
                executor.add_node(node)
            spinner = threading.Thread(target=spin, name="stage-spin", daemon=True)
            with recording(stage, args, "teleop.py"), viewing(stage, args):
                spinner.start()
                try:
                    with KeyReader(sys.stdin) as keys:
                        teleop.run(keys)
                finally:  # the world stops stepping before the recording is written
                    done.set()
                    spinner.join()
        return 0
    except (WorldError, FileNotFoundError, ValueError) as error:
        print(f"teleop.py: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 0
    finally:
        done.set()
        for node in nodes:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
