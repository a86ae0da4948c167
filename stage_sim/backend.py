"""Kernel settings, the bottom layer: which implementation runs the hot paths, on how many threads, and
where numba caches them. It imports nothing of stage_sim, so every layer (the wanderer too) reads them here.

Two implementations exist and give identical answers (``tests/sensing``, ``tests/sim``):

* ``"numba"`` (default): compiled kernels; parallel over rays and bodies when ``threads > 1``.
* ``"numpy"``: the vectorised reference.

Which code each name runs is decided in one place, :func:`stage_sim.sim.backends.backend_for`.

Choice, strongest first: the explicit argument (``Simulation(kernels=...)``, ``--kernels``), the
environment variable ``STAGE_SIM_KERNELS``, the default ``numba``. If numba cannot be imported the
numpy path runs after a one-line warning. A :class:`~stage_sim.sim.simulation.Simulation` whose kernels
nobody chose reaches the default through :mod:`stage_sim.sim.kernel_upgrade` (numpy first, numba once it
has loaded in the background). Threads likewise: argument, ``STAGE_SIM_THREADS``, 1.

Compiled kernels are cached on disk (``cache=True``) next to the package, or, when that folder is not
writable (a system-wide install), in ``~/.cache/stage_sim`` (``NUMBA_CACHE_DIR`` when set wins). The
first compilation logs "compiling simulation kernels, once"; ``make setup`` runs
:mod:`stage_sim.sim.warm_up` to fill the cache.
"""

from __future__ import annotations

import logging
import os
import sys
import warnings
from functools import cache
from pathlib import Path

KERNELS = ("numba", "numpy")
KERNELS_ENV = "STAGE_SIM_KERNELS"
THREADS_ENV = "STAGE_SIM_THREADS"
_PACKAGE = Path(__file__).resolve().parent

log = logging.getLogger("stage_sim")


def resolve_kernels(requested: str | None = None) -> str:
    """``"numba"`` or ``"numpy"``: the argument, else ``$STAGE_SIM_KERNELS``, else numba (if it imports)."""
    choice = requested or os.environ.get(KERNELS_ENV) or "numba"
    if choice not in KERNELS:
        raise ValueError(f"kernels must be one of {', '.join(KERNELS)}, not {choice!r}")
    if choice == "numba" and not numba_available():
        return "numpy"
    return choice


def resolve_threads(requested: int | None = None, default: int = 1) -> int:
    """Threads for the kernels: the argument, else ``$STAGE_SIM_THREADS``, else ``default``; 0 = all cores."""
    value = requested
    if value is None:
        env = os.environ.get(THREADS_ENV, "").strip()
        value = int(env) if env else default
    if value < 0:
        raise ValueError(f"threads must be >= 0, not {value}")
    return available_cores() if value == 0 else value


def available_cores() -> int:
    """The cores this process may run on (its affinity, e.g. under ``taskset``)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


@cache
def numba_available() -> bool:
    """Import numba once (with the cache folder set up first); warn in one line if it is missing."""
    _configure_cache_dir()
    try:
        import numba  # noqa: F401
    except Exception as error:  # an incompatible or broken numba is as good as none
        warnings.warn(f"numba unavailable ({error}); using the numpy kernels", RuntimeWarning, stacklevel=3)
        return False
    return True


def set_threads(threads: int) -> None:
    """Let the next parallel kernel call use ``threads`` threads (capped at numba's pool size)."""
    import numba

    numba.set_num_threads(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))


def announce_compilation(*dispatchers) -> None:
    """Log "compiling simulation kernels, once" if some kernel is neither compiled nor cached on disk."""
    for dispatcher in dispatchers:
        if dispatcher.overloads:  # compiled already (``signatures`` lists them: 2 % of an obstacles episode's reset)
            continue
        try:
            index = Path(dispatcher._cache._cache_file._index_path)  # numba internals: the cache index
        except AttributeError:
            return
        if not index.exists():
            log.warning("compiling simulation kernels, once (cached in %s)", index.parent)
            return


def _configure_cache_dir() -> None:
    """Point numba's cache at ``~/.cache/stage_sim`` when the package folder cannot hold it."""
    if os.environ.get("NUMBA_CACHE_DIR") or os.access(_PACKAGE, os.W_OK):
        return
    user_cache = Path.home() / ".cache" / "stage_sim"
    user_cache.mkdir(parents=True, exist_ok=True)
    os.environ["NUMBA_CACHE_DIR"] = str(user_cache)
    if "numba" in sys.modules:  # imported before us: tell its config too
        sys.modules["numba"].config.CACHE_DIR = str(user_cache)

