"""``stage_sim run WORLD [--duration S] [--bag OUT.mcap]``: step a world without ROS, optionally into a ROS 2 bag.

The bag holds what ``stageros --bag`` records for the same world, seed and commands (same topics, frames,
types, QoS and field values) but comes from the core alone: no rclpy, no ROS install. Steps are paced as
every entry point paces them (:class:`~stage_sim.runs.pacing.Pacer`). The run ends at ``--duration`` sim
seconds or the world's ``quit_time``, whichever comes first, or on Ctrl-C / SIGTERM; each finalises the bag.
Exit status 0 (also after Ctrl-C during the run), 1 when the bag could not be written to the end, 2 for bad
input, 130 for Ctrl-C before the first step.
"""

from __future__ import annotations

import argparse
import signal
import sys
import time
from pathlib import Path
from typing import Any

from stage_sim.cli.arguments import (
    add_duration_argument,
    add_kernel_arguments,
    add_seed_argument,
    add_speedup_argument,
)
from stage_sim.cli.controllers import CONTROLLERS, STRAIGHT_SPEED
from stage_sim.runs.interrupts import stop_requests


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
    from stage_sim.runs.pacing import Pacer, run_end, run_speedup, threads_for_run
    from stage_sim.sim.simulation import Simulation
    from stage_sim.worldfile.loader import load_world

    description = load_world(args.world)
    speedup = run_speedup(args.speedup, description.settings.speedup)
    threads = threads_for_run(args.threads, speedup, recording=bool(args.bag))
    sim = Simulation(description, seed=args.seed, kernels=args.kernels, threads=threads)
    for warning in sim.warnings:
        print(f"stage_sim run: {warning}", file=sys.stderr)
    recorder = None
    if args.bag:
        names = [robot_names(r.index, r.name, len(sim.robots), len(r.rangers), args.use_model_names)
                 for r in sim.robots]
        try:
            recorder = BagRecorder(sim, args.bag, names, topics=args.bag_topics, with_map=args.map,
                                   prog="stage_sim run", speedup=speedup)
        except (BagError, ValueError) as exc:
            print(f"stage_sim run: {exc}", file=sys.stderr)
            return 2
    pacer = Pacer(sim.interval, speedup, lambda: sim.sim_time, run_end(description.settings.quit_time, args.duration))
    drive = CONTROLLERS[args.controller](sim, args.seed)
    start = time.monotonic()
    try:
        with stop_requests() as stop:  # Ctrl-C and SIGTERM end the run between steps
            while not (pacer.finished() or stop.is_set() or (recorder and recorder.failed)):
                for _ in pacer.steps():
                    drive()
                    sim.step()
                    if recorder:
                        recorder.record_step()
                stop.wait(pacer.wait_s())
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
        description="Step a world until --duration sim seconds or its quit_time, whichever comes first (neither: "
        "until Ctrl-C), with every robot driven by --controller, and record with --bag what stageros would "
        "publish, into an MCAP bag that rosbags, the mcap tools and 'ros2 bag' read. No ROS installation is needed.",
    )
    parser.add_argument("world", help="world file path, or the name of a bundled world")
    add_duration_argument(parser)
    add_speedup_argument(parser)
    parser.add_argument(
        "--controller", choices=sorted(CONTROLLERS), default="straight",
        help=f"who drives: 'straight' at {STRAIGHT_SPEED} m/s, or the wander node's strategy (default straight)")
    add_seed_argument(parser)
    add_kernel_arguments(parser)
    parser.add_argument("-u", action="store_true", dest="use_model_names",
                        help="name robots' topics and frames after their models (as stageros -u)")
    parser.add_argument("--bag", type=Path, metavar="OUT.mcap", help="record a ROS 2 bag (MCAP) of the run")
    parser.add_argument("--bag-topics", nargs="+", metavar="T",
                        help="record only these topics (e.g. /clock robot_0/base_scan; default: all)")
    parser.add_argument("--map", action="store_true", help="also record /map (as stageros' publish_map parameter)")
    parser.set_defaults(run=run)
