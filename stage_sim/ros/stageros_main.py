"""``stageros [-g] [-u] [--view-*] [--speedup X] [--seed N] [--kernels K] [--threads N]
[--bag OUT.mcap] WORLD [--ros-args ...]``.

Unless ``-g`` is given it serves the browser view (:mod:`stage_sim.ros.view`) and prints its URL. A broken
world prints ``file:line:column: ...`` and exits with status 2 (no traceback); Ctrl-C and the world's
``quit_time`` end the node cleanly with status 0.
"""

from __future__ import annotations

import argparse
import os
import sys

# Project rule: discovery stays on loopback unless the user chose otherwise (set before rclpy loads).
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import rclpy
import rclpy.logging
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args

from stage_sim.bags.errors import BagError
from stage_sim.cli.arguments import add_kernel_arguments, add_seed_argument, add_speedup_argument
from stage_sim.ros.bag_recording import add_bag_arguments, bag_recording
from stage_sim.ros.core_log import core_log_on
from stage_sim.ros.recording import add_record_arguments, recording
from stage_sim.ros.view import add_view_options, viewing
from stage_sim.runs.interrupts import stop_requests
from stage_sim.worldfile.bundled import bundled_worlds
from stage_sim.worldfile.errors import WorldError


def parse_args(argv: list[str]) -> argparse.Namespace:
    """Command-line options after ROS arguments have been removed."""
    parser = argparse.ArgumentParser(
        prog="stageros", description="Simulate a Stage world and publish it like stage_ros' stageros.",
        epilog=f"bundled worlds: {', '.join(bundled_worlds()) or 'none installed'}")
    add_view_options(parser)
    parser.add_argument("-u", action="store_true", dest="use_model_names",
                        help="name robots' topics and frames after their models instead of robot_<i>")
    add_speedup_argument(parser)
    add_seed_argument(parser)
    add_kernel_arguments(parser)
    add_record_arguments(parser)
    add_bag_arguments(parser)
    parser.add_argument("world", nargs="?", default=None,
                        help="a .world file, or a bundled world's name (else the 'world_file' parameter)")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Run stageros until Ctrl-C, shutdown or the world's quit_time; returns the exit status."""
    argv = list(sys.argv if argv is None else argv)
    args = parse_args(remove_ros_args(argv)[1:])
    from stage_sim.ros.stageros import StageRos

    # Ctrl-C/SIGTERM end the loop between spins: rclpy's own handlers shut the context down mid-step, and the
    # step then fails to publish with a traceback.
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    node = None
    try:
        with stop_requests() as stop, core_log_on(rclpy.logging.get_logger("stageros")):
            node = StageRos(
                args.world, speedup=args.speedup, seed=args.seed, use_model_names=args.use_model_names or None,
                kernels=args.kernels, threads=args.threads, recording=bool(args.bag))
            executor = SingleThreadedExecutor()
            executor.add_node(node)
            with (recording(node, args, "stageros"), viewing(node, args),
                  bag_recording(node, args, "stageros") as recorder):
                while rclpy.ok() and not node.finished and not stop.is_set():
                    executor.spin_once(timeout_sec=0.1)
        return 0 if recorder is None or recorder.summary.complete else 1
    except (WorldError, FileNotFoundError, ValueError, BagError) as error:
        print(f"stageros: {error}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, ExternalShutdownException):
        return 0
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
