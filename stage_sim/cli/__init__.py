"""The ``stage_sim`` console script: ROS-free tools around world files, one module per subcommand.

``stage_sim inspect WORLD [--json]`` shows what the simulator will make of a world; ``stage_sim render WORLD
-o out.png`` draws it (``-o out.gif`` records a run); ``stage_sim view WORLD`` runs it live in the browser.
Exit status 0 on success, 2 when the world cannot be loaded (the message, with file:line:column, goes to
stderr). A new subcommand is a module with ``add_command(subparsers)`` that sets ``run``, listed in
:data:`COMMANDS`.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import Any

from stage_sim.cli import inspect, recover, render, run, view
from stage_sim.worldfile.errors import WorldError

COMMANDS: list[Callable[[Any], None]] = [
    inspect.add_command, render.add_command, view.add_command, run.add_command, recover.add_command,
]
"""Each entry adds one subcommand and sets ``run``."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="stage_sim", description="Tools around Stage world files that need no ROS: look inside a world, "
        "draw it, run it live in the browser, run it into a ROS 2 bag, mend a bag cut short.",
        epilog="'stage_sim COMMAND --help' tells more. Exit status 2 when a world cannot be loaded (file:line:column "
        "on stderr).")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in COMMANDS:
        add(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Console-script entry point; returns the exit status."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.run(args))
    except WorldError as exc:
        print(exc, file=sys.stderr)
        return 2
