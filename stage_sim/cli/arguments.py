"""What the commands share: argument types with clear errors, and the options every command that runs a world
spells the same way (``stage_sim``'s subcommands, ``stageros``, the launch scripts)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from stage_sim.backend import KERNELS, KERNELS_ENV, THREADS_ENV


def image_path(text: str) -> Path:
    path = Path(text)
    if path.suffix.lower() not in (".png", ".gif"):
        raise argparse.ArgumentTypeError(f"'{text}' must end in .png or .gif")
    return path


def positive(text: str) -> float:
    value = float(text)
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be a positive number, not {text}")
    return value


def count(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be 0 or more, not {text}")
    return value


def add_speedup_argument(parser: argparse.ArgumentParser) -> None:
    """``--speedup X``: None when absent, so that the world's own ``speedup`` applies."""
    parser.add_argument("--speedup", type=float, default=None,
                        help="sim seconds per wall second (world's 'speedup' if absent; <= 0: as fast as possible)")


def add_seed_argument(parser: argparse.ArgumentParser, default: int | None = None) -> None:
    """``--seed N`` of everything a run draws: odometry errors, sensor noise, the wanderers."""
    drawn = "fresh ones every run" if default is None else default
    parser.add_argument("--seed", type=int, default=default,
                        help=f"seed of odometry errors, sensor noise and any wanderer (default: {drawn})")


def add_duration_argument(parser: argparse.ArgumentParser) -> None:
    """``--duration S``: None when absent; the run ends at the earlier of it and the world's ``quit_time``
    (:func:`stage_sim.runs.pacing.run_end`)."""
    parser.add_argument("--duration", type=positive, default=None,
                        help="sim seconds to run; the run also ends at the world's quit_time if that comes first "
                             "(default: the world's quit_time, else until Ctrl-C)")


def add_kernel_arguments(parser: argparse.ArgumentParser, paced: bool = True) -> None:
    """``--kernels`` and ``--threads``, the same on every command that simulates; a ``paced`` command (one with
    ``--speedup``) takes all cores when unpaced, all but one when it records a bag
    (:func:`stage_sim.runs.pacing.threads_for_run`)."""
    threads_default = "1, all cores with --speedup 0 (all but one when recording a bag)" if paced else "1"
    parser.add_argument("--kernels", choices=KERNELS, default=None,
                        help=f"hot-path implementation, identical results (default: ${KERNELS_ENV} or numba)")
    parser.add_argument("--threads", type=int, default=None,
                        help=f"kernel threads, 0 = all cores, identical results (default: ${THREADS_ENV} or "
                             f"{threads_default})")
