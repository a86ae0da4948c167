"""``stage_sim render WORLD -o out.png|out.gif``: draw a world as Stage's window would, or record a run as a GIF."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from stage_sim.cli.arguments import add_kernel_arguments, add_seed_argument, count, image_path, positive
from stage_sim.cli.controllers import CONTROLLERS, STRAIGHT_SPEED


def run(args: argparse.Namespace) -> int:
    from stage_sim.rendering.recorder import Recorder
    from stage_sim.sim.simulation import Simulation

    sim = Simulation.from_world(args.world, seed=args.seed, kernels=args.kernels, threads=args.threads)
    output = args.output or Path(f"{Path(args.world).stem}.png")
    try:
        recorder = Recorder(
            sim, output, every_s=args.record_every, fps=args.record_fps, trail_s=args.trail,
            scale=args.scale, lasers=not args.no_lasers, grid=args.grid,
        )
    except ValueError as exc:
        print(f"stage_sim render: {exc}", file=sys.stderr)
        return 2
    drive = CONTROLLERS[args.controller](sim, args.seed)
    for _ in range(args.steps):
        drive()
        sim.step()
        recorder.capture_if_due()
    try:
        recorder.close()
    except OSError as exc:
        print(f"stage_sim render: cannot write {output}: {exc}", file=sys.stderr)
        return 1
    print(f"{output}: {recorder.frame_count} frame(s) up to sim time {sim.sim_time:g} s")
    return 0


def add_command(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "render", help="draw a world (optionally after some steps) to a PNG, or record the steps as a GIF",
        description="Draw the world, its robots and their lasers as Stage's window would. An output ending in "
        ".gif records a frame every --record-every sim seconds of the --steps run; .png is the final state.",
    )
    parser.add_argument("world", help="world file path, or the name of a bundled world")
    parser.add_argument("-o", "--output", type=image_path, help="output .png or .gif (default: WORLD-NAME.png)")
    parser.add_argument("--scale", type=positive, help="pixels per metre (default: the world's window scale)")
    parser.add_argument("--no-lasers", action="store_true", help="do not draw the laser rays")
    parser.add_argument("--grid", action="store_true", help="draw a 1 m grid")
    add_seed_argument(parser, default=0)
    add_kernel_arguments(parser, paced=False)
    parser.add_argument("--steps", type=count, default=0, help="steps to simulate first (default: 0)")
    parser.add_argument(
        "--controller", choices=sorted(CONTROLLERS), default="straight",
        help=f"who drives during --steps: 'straight' at {STRAIGHT_SPEED} m/s, or the wander node's strategy",
    )
    parser.add_argument("--trail", type=float, default=10.0, help="sim seconds of path drawn behind robots (0: none)")
    parser.add_argument("--record-every", type=positive, default=0.5, help="sim seconds between GIF frames")
    parser.add_argument("--record-fps", type=positive, help="GIF playback frames per second (default: real time)")
    parser.set_defaults(run=run)
