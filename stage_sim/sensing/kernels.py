"""The command-line kernel options and the threads of a paced run (the settings themselves:
:mod:`stage_sim.backend`)."""

from __future__ import annotations

import argparse
import os

from stage_sim.backend import KERNELS, KERNELS_ENV, THREADS_ENV, resolve_threads


def add_kernel_arguments(parser: argparse.ArgumentParser, threads_default: str = "1") -> None:
    """``--kernels`` and ``--threads``, the same on every command that simulates."""
    parser.add_argument("--kernels", choices=KERNELS, default=None,
                        help=f"hot-path implementation, identical results (default: ${KERNELS_ENV} or numba)")
    parser.add_argument("--threads", type=int, default=None,
                        help=f"kernel threads, 0 = all cores, identical results (default: ${THREADS_ENV} or "
                             f"{threads_default})")


def let_idle_threads_sleep(realtime: bool, threads: int) -> None:
    """Before a run paced to the wall clock on more than one thread: make numba's OpenMP workers sleep
    between the step's parallel loops instead of spinning through the pause (libgomp's default, right for
    back-to-back steps: stageros with 100 robots at real time on 2 threads used 18 % of a core, 7 % without;
    6.6 % on one thread). Acts only if the thread pool has not started yet; a user's own
    ``OMP_WAIT_POLICY`` wins."""
    if realtime and threads > 1:
        os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")


def threads_for_run(requested: int | None, speedup: float) -> int:
    """Threads of a run at ``speedup`` (<= 0: as fast as possible): the argument, else ``$STAGE_SIM_THREADS``,
    else 1 when paced to the wall clock and all cores when not; idle workers of a paced run then sleep
    (:func:`let_idle_threads_sleep`). What ``stageros``, ``stage_sim run`` and ``stage_sim view`` use."""
    threads = resolve_threads(requested, default=0 if speedup <= 0 else 1)
    let_idle_threads_sleep(speedup > 0, threads)
    return threads
