"""``stage_sim view WORLD [--controller wander] [--speedup X]``: run a world live in the browser, without ROS.

Prints ``view: http://127.0.0.1:PORT/`` once and steps the world in real time × ``--speedup`` until
Ctrl-C, ``--duration`` sim seconds or the world's ``quit_time``, whichever comes first. Commands from the
page's keys stop after ``--watchdog`` sim seconds without a new one, as ``stageros``' ``base_watchdog_timeout``
does.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from typing import Any

from stage_sim.cli.arguments import (
    add_duration_argument,
    add_kernel_arguments,
    add_seed_argument,
    add_speedup_argument,
)
from stage_sim.runs.pacing import WATCHDOG_S
from stage_sim.view.options import add_view_arguments


def run(args: argparse.Namespace) -> int:
    from stage_sim.runs.pacing import run_end, run_speedup, threads_for_run
    from stage_sim.sim.simulation import Simulation
    from stage_sim.view import LiveView, PacedLoop, view_settings
    from stage_sim.worldfile.loader import load_world

    description = load_world(args.world)
    speedup = run_speedup(args.speedup, description.settings.speedup)
    sim = Simulation(description, seed=args.seed, watchdog_timeout=args.watchdog, kernels=args.kernels,
                     threads=threads_for_run(args.threads, speedup))
    for warning in sim.warnings:
        print(f"stage_sim view: {warning}", file=sys.stderr)
    before_step = None
    if args.controller == "wander":
        from stage_sim.runs.driver import WanderDriver

        before_step = WanderDriver(sim, args.seed).decide
    loop = PacedLoop(sim, speedup, before_step, run_end(description.settings.quit_time, args.duration))
    view = LiveView(sim, loop, view_settings(args))
    try:
        view.start()
    except OSError as exc:
        print(f"stage_sim view: cannot serve the view: {exc}", file=sys.stderr)
        return 1
    stop = threading.Event()
    previous = signal.signal(signal.SIGINT, lambda *_: stop.set())
    try:
        loop.run(stop, view)
    finally:
        signal.signal(signal.SIGINT, previous)
        view.close()
    return 0


def add_command(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "view", help="run a world live in the browser (no ROS): watch, drag, pause and drive the robots",
        description="Simulate WORLD in real time and serve a page that shows it and controls it as Stage's "
        "window does. Prints the page's URL; Ctrl-C, --duration or the world's quit_time stops.",
    )
    parser.add_argument("world", help="world file path, or the name of a bundled world")
    parser.add_argument("--controller", choices=["none", "wander"], default="none",
                        help="who drives: nobody but you (default), or the wander node's strategy on every robot")
    add_speedup_argument(parser)
    add_seed_argument(parser)
    add_kernel_arguments(parser)
    parser.add_argument("--watchdog", type=float, default=WATCHDOG_S,
                        help=f"sim seconds a command lasts without a new one (default {WATCHDOG_S}; <= 0: forever)")
    add_duration_argument(parser)
    add_view_arguments(parser)
    parser.set_defaults(run=run)
