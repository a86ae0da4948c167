"""``stage_sim run WORLD --duration S [--bag OUT.mcap]``: step a world without ROS, optionally into a ROS 2 bag.

The bag holds what ``stageros --bag`` records for the same world, seed and commands (same topics, frames,
types, QoS and field values) but comes from the core alone: no rclpy, no ROS install. The run ends at
``--duration`` sim seconds, at the world's ``quit_time`` or on Ctrl-C / SIGTERM; each finalises the bag.
Exit status 0 (also after Ctrl-C during the run), 1 when the bag misses steps (dropped at real time) or
could not be written to the end, 2 for bad input, 130 for Ctrl-C before the first step.
"""

from __future__ import annotations

import argparse
import signal
import sys
import time
from pathlib import Path
from typing import Any

from stage_sim.cli.arguments import positive, resolve_world
from stage_sim.cli.controllers import CONTROLLERS, STRAIGHT_SPEED
from stage_sim.runs.interrupts import stop_requests
from stage_sim.sensing.kernels import add_kernel_arguments


def run(args: argparse.Namespace) -> int:
    if (args.bag_topics or args.map) and not args.bag:
        print("stage_sim run: --bag-topics and --map choose what --bag records; give --bag OUT.mcap", file=sys.stderr)
        return 2
    previous = signal.signal(signal.SIGTERM, signal.default_int_handler)
    try:
        return _run(args)
    except KeyboardInterrupt:  # before the first step: there is nothing to finalise
        print("stage_sim run: interrupted", file=sys.stderr)
        return 130
    finally:
        signal.signal(signal.SIGTERM, previous)


def _run(args: argparse.Namespace) -> int:
    from stage_sim.bags.errors import BagError
    from stage_sim.bags.recorder import BagRecorder
    from stage_sim.interface.names import robot_names
    from stage_sim.sensing.kernels import threads_for_run
    from stage_sim.sim.simulation import Simulation
    from stage_sim.worldfile.loader import load_world

    description = load_world(resolve_world(args.world))
    speedup = description.settings.speedup if args.speedup is None else args.speedup
    threads = threads_for_run(args.threads, speedup)
    sim = Simulation(description, seed=args.seed, kernels=args.kernels, threads=threads)
    for warning in sim.warnings:
        print(f"stage_sim run: {warning}", file=sys.stderr)
    recorder = None
    if args.bag:
        names = [robot_names(r.index, r.name, len(sim.robots), len(r.rangers), args.use_model_names)
                 for r in sim.robots]
        try:
            recorder = BagRecorder(sim, args.bag, names, topics=args.bag_topics, with_map=args.map,
                                   prog="stage_sim run", lossless=speedup <= 0)
        except (BagError, ValueError) as exc:
            print(f"stage_sim run: {exc}", file=sys.stderr)
            return 2
    end = args.duration
    if description.settings.quit_time > 0:
        end = min(end, description.settings.quit_time)
    drive = CONTROLLERS[args.controller](sim, args.seed)
    start = time.monotonic()
    try:
        with stop_requests() as stop:  # Ctrl-C and SIGTERM end the run between steps
            while sim.sim_time < end - 1e-9 and not (recorder and recorder.failed) and not stop.is_set():
                drive()
                sim.step()
                if recorder:
                    recorder.record_step()
                if speedup > 0:
                    stop.wait(max(0.0, start + sim.sim_time / speedup - time.monotonic()))
        if stop.is_set():
            print(f"stage_sim run: interrupted at sim time {sim.sim_time:g} s", file=sys.stderr)
    finally:
        summary = recorder.close() if recorder else None
    wall = time.monotonic() - start
    print(f"{description.path.name}: {sim.sim_time:g} s of sim time in {wall:.2f} s of wall time "
          f"({sim.sim_time / wall if wall > 0 else float('inf'):.1f}x real time; {sim.kernels} kernels, "
          f"{sim.threads} thread{'s' if sim.threads > 1 else ''})")
    if summary:
        print(summary.describe(), file=sys.stderr if summary.error or summary.dropped_steps else sys.stdout)
    return 0 if summary is None or summary.complete else 1


def add_command(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "run", help="run a world without ROS for some sim time, optionally recording a ROS 2 bag (MCAP)",
        description="Step a world for --duration sim seconds (or until its quit_time or Ctrl-C) with every robot "
        "driven by --controller, and record with --bag what stageros would publish, into an MCAP bag that "
        "rosbags, the mcap tools and 'ros2 bag' read. No ROS installation is needed.",
    )
    parser.add_argument("world", help="world file path, or the name of a bundled world")
    parser.add_argument("--duration", type=positive, required=True, help="sim seconds to run")
    parser.add_argument("--speedup", type=float, default=None,
                        help="sim seconds per wall second (world's 'speedup' if absent; <= 0: as fast as possible)")
    parser.add_argument(
        "--controller", choices=sorted(CONTROLLERS), default="straight",
        help=f"who drives: 'straight' at {STRAIGHT_SPEED} m/s, or the wander node's strategy (default straight)")
    parser.add_argument("--seed", type=int, default=None, help="simulation (and wanderer) seed")
    add_kernel_arguments(parser, threads_default="1, all cores with --speedup 0")
    parser.add_argument("-u", action="store_true", dest="use_model_names",
                        help="name robots' topics and frames after their models (as stageros -u)")
    parser.add_argument("--bag", type=Path, metavar="OUT.mcap", help="record a ROS 2 bag (MCAP) of the run")
    parser.add_argument("--bag-topics", nargs="+", metavar="T",
                        help="record only these topics (e.g. /clock robot_0/base_scan; default: all)")
    parser.add_argument("--map", action="store_true", help="also record /map (as stageros' publish_map parameter)")
    parser.set_defaults(run=run)
