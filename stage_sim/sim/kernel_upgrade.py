"""Start on the numpy kernels, switch to numba when it is ready: the first scan does not wait for numba.

Importing numba and loading even cached kernels costs a process 1.5-2.5 s on the project's machines, longer
than everything else stageros does before its first scan. Both implementations give identical answers bit
for bit (``tests/sim/test_kernel_identity.py``), so a simulation whose kernels were not chosen explicitly
steps on the numpy reference at first while one background thread imports numba and builds the compiled
collision checker and ray casters; between two steps the simulation adopts them. Nothing a user observes
changes except speed (and :attr:`Simulation.kernels`, which says which implementation runs now).

The upgrade is used only when nobody chose: no ``kernels`` argument, no ``$STAGE_SIM_KERNELS``, numba's
kernels not yet loaded in this process (a second simulation gets them at once), and a world with at most
:data:`MAX_NUMPY_BEAMS` laser beams (a swarm or a 1081-beam crowd would crawl on numpy meanwhile).
"""

from __future__ import annotations

import logging
import os
import time
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from stage_sim.backend import KERNELS_ENV, numba_available
from stage_sim.sim.backends import Backend, backend_for

log = logging.getLogger("stage_sim")
_LOADED = {"numba": False}  #: per kernels name: whether some simulation of this process runs on them


def numba_loaded() -> bool:
    """Whether some simulation of this process already runs the compiled kernels."""
    return _LOADED["numba"]


def note_kernels_running(kernels: str) -> None:
    """Record that a simulation runs on ``kernels``: once on numba's, later simulations use them from the start."""
    _LOADED[kernels] = True


#: Beams per step above which the numpy reference would make the first seconds slow (it walks ~0.3 M rays/s):
#: larger worlds wait for numba before their first step instead.
MAX_NUMPY_BEAMS = 4096


def upgrade_wanted(kernels: str | None, beams: int) -> bool:
    """True when nobody chose the kernels, numba's are not loaded yet and the world's ``beams`` per step are
    few enough for the numpy reference: start on numpy, upgrade later."""
    return kernels is None and not os.environ.get(KERNELS_ENV) and not numba_loaded() and beams <= MAX_NUMPY_BEAMS


class Upgradable(Protocol):
    """What the upgrade needs of a simulation (:class:`~stage_sim.sim.simulation.Simulation`)."""

    robots: list
    start_poses: np.ndarray
    threads: int
    drives: Any

    def build_parts(self, kernels: str) -> tuple[Any, Any]: ...


@dataclass(frozen=True)
class CompiledParts:
    """What a simulation swaps in: the compiled collision checker and ray sensing, the backend they are of (its
    motion kernels, its name) and their fused step (None: the world steps role by role)."""

    collision: Any
    sensing: Any
    backend: Backend
    fused: Any


class KernelUpgrade:
    """Builds a simulation's compiled parts on one background thread, started after its first step."""

    def __init__(self, sim: Upgradable) -> None:
        self._sim = sim
        self._future: Future | None = None
        self._adopted = False
        self._started = 0.0

    def poll(self) -> CompiledParts | None:
        """Call after each step: starts the build the first time, returns the parts once (when built).

        A build that fails (numba missing or broken) leaves the simulation on numpy for good."""
        if self._future is None:
            self._started = time.monotonic()
            pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="stage_sim-kernels")
            self._future = pool.submit(build_compiled_parts, self._sim)
            pool.shutdown(wait=False)  # the one job runs on; the thread ends with it
            return None
        if self._adopted or not self._future.done():
            return None
        self._adopted = True
        try:
            parts = self._future.result()
        except Exception as error:  # a kernel that cannot load must not stop a running simulation
            log.warning("compiled kernels unavailable (%s); staying on the numpy kernels", error)
            return None
        if parts is not None:
            log.info("simulation kernels: numba (ready %.1f s after the first step)", time.monotonic() - self._started)
        return parts

    def wait(self, timeout: float | None = None) -> None:
        """Block until the background build (if started) has finished; for tests and benchmarks."""
        if self._future is not None:
            self._future.exception(timeout)


def build_compiled_parts(sim: Upgradable) -> CompiledParts | None:
    """The compiled collision checker, sensing and motion kernels for ``sim``, each run once so that the
    main thread never waits for numba's loading; None when numba is unavailable."""
    if not numba_available():
        return None
    backend = backend_for("numba")
    collision, sensing = sim.build_parts(backend.name)
    backend.motion.warm(len(sim.robots))
    poses = sim.start_poses
    collision.overlapping(poses)
    collision.resolve(poses, poses, np.full_like(poses, 1e-3), 0.1, np.ones(len(poses), dtype=bool))  # loads the
    # raster and decision kernels (nothing is kept)
    sensing.sense(poses, 0.0)
    fused = backend.fused(collision, sensing.single_cast(), sim.threads, sim.drives)
    if fused is not None:
        fused.warm(poses)
    note_kernels_running(backend.name)
    return CompiledParts(collision, sensing, backend, fused)
