"""Child processes for the corpus tests: a memory limit, a wall timeout and the CPU time they used.

Every world runs in a child whose address space is capped, so that a world that would grow without
bound (as Stage's SFU.world and large.world did before the sparse world) fails there, never takes the
machine down, and never leaves pytest itself short of memory.

Most of a child's time is its start and its exit (imports, numba's kernels loading in the background), one
core's work: :class:`RunsAhead` runs a test's worlds two at a time, each ROS child on a domain of its own.
"""

from __future__ import annotations

import contextlib
import os
import queue
import re
import resource
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pytest

MEMORY_LIMIT_BYTES = 4 * 1024**3
WALL_TIMEOUT_S = 60.0
"""A safety net only: ``stage_sim inspect``'s 10 s budget is checked on the child's CPU time (a loaded machine
inflates wall time more)."""
CPU_BUDGET_S = 10.0
LOCATED_MESSAGE = re.compile(r"^(?:\S+: )?(?P<file>[^:\s]+):(?P<line>\d+):(?P<column>\d+): \S", re.MULTILINE)
"""``[prog: ]file:line:col: message`` (stageros prefixes its name)."""
REPO = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class ChildRun:
    returncode: int | None
    """None when the child was still running at the wall timeout (it is killed)."""
    stdout: str
    stderr: str
    cpu_seconds: float
    """CPU seconds of the whole run."""


def _cap_memory() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT_BYTES, MEMORY_LIMIT_BYTES))


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def python_command(*args: str) -> list[str]:
    """This interpreter (the venv's) running ``args``."""
    return [sys.executable, *args]


def console_script(name: str) -> str:
    """A console script installed beside this interpreter (the venv's ``bin/``)."""
    return str(Path(sys.executable).with_name(name))


def run_limited(command: list[str], ready: re.Pattern[str] | None = None,
                env: dict[str, str] | None = None) -> ChildRun:
    """Run ``command`` with capped memory until it exits (or the wall timeout); with ``ready``, interrupt
    it (Ctrl-C) as soon as a line of its stderr matches, as a user stops a simulator that has come up.
    ``env``: the child's environment (default: this process's). Its ``cpu_seconds`` hold only while no other
    child of this process runs meanwhile."""
    cpu_before = _children_cpu()
    if ready is None:
        try:
            done = subprocess.run(command, capture_output=True, text=True, preexec_fn=_cap_memory, cwd=REPO,
                                  timeout=WALL_TIMEOUT_S, env=env)
        except subprocess.TimeoutExpired as expired:
            return ChildRun(None, str(expired.stdout or ""), str(expired.stderr or ""), _children_cpu() - cpu_before)
        return ChildRun(done.returncode, done.stdout, done.stderr, _children_cpu() - cpu_before)
    child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                             preexec_fn=_cap_memory, cwd=REPO, env=env)
    lines: queue.Queue[str | None] = queue.Queue()
    threading.Thread(target=lambda: [*map(lines.put, child.stderr), lines.put(None)], daemon=True).start()
    stderr: list[str] = []
    interrupted = False
    deadline = time.monotonic() + WALL_TIMEOUT_S
    while True:
        try:
            line = lines.get(timeout=max(0.0, deadline - time.monotonic()))
        except queue.Empty:
            child.kill()
            child.wait()
            return ChildRun(None, "", "".join(stderr), _children_cpu() - cpu_before)
        if line is None:
            break
        stderr.append(line)
        if ready.search(line) and not interrupted:
            interrupted = True
            child.send_signal(signal.SIGINT)
    returncode = child.wait()
    return ChildRun(returncode, "", "".join(stderr), _children_cpu() - cpu_before)


#: Children run at once by :class:`RunsAhead`: this machine's two cores.
AT_ONCE = 2


class RunsAhead:
    """The runs of one parametrised test, started ahead, :data:`AT_ONCE` at a time, in the order pytest will ask
    for them (only those it selected): a test waits for its own run, the next ones run meanwhile. ``start`` makes
    a world's run from its path and its child's environment (None: this process's). With ``domains``
    (:func:`ros_domains`) each child runs on a ``ROS_DOMAIN_ID`` no other running child has, so that no two
    simulators discover each other."""

    def __init__(self, request: pytest.FixtureRequest, test: str,
                 start: Callable[[Path, dict[str, str] | None], ChildRun], domains: list[str] | None = None) -> None:
        chosen = [item.callspec.params["world"] for item in request.session.items
                  if item.module is request.module and getattr(item, "originalname", None) == test]
        self._free: queue.Queue[dict[str, str] | None] = queue.Queue()
        for domain in domains or [None] * AT_ONCE:
            self._free.put(None if domain is None else {**os.environ, "ROS_DOMAIN_ID": domain})
        self._pool = ThreadPoolExecutor(max_workers=AT_ONCE, thread_name_prefix="corpus-child")
        self._runs = {world.id: self._pool.submit(self._run, start, world.path) for world in chosen}

    def _run(self, start: Callable[[Path, dict[str, str] | None], ChildRun], path: Path) -> ChildRun:
        env = self._free.get()
        try:
            return start(path, env)
        finally:
            self._free.put(env)

    def result(self, world_id: str) -> ChildRun:
        """The run of ``world_id`` once it has ended."""
        return self._runs[world_id].result()

    def close(self) -> None:
        """Drop the runs not begun (a test module stopped early) and wait for those under way."""
        for run in self._runs.values():
            run.cancel()
        self._pool.shutdown(wait=True)


@contextlib.contextmanager
def ros_domains() -> Iterator[list[str]]:
    """:data:`AT_ONCE` ROS domains: this session's and others reserved for as long as the context lasts
    (``domain_coordinator``, as tests/conftest.py reserves the session's; without it, the next domains after
    this session's, as its fallback picks that one by process id)."""
    own = os.environ["ROS_DOMAIN_ID"]
    try:
        from domain_coordinator import domain_id
    except ImportError:
        yield [own, *(str(1 + (int(own) + k - 1) % 100) for k in range(1, AT_ONCE))]
        return
    with contextlib.ExitStack() as stack:
        others = []
        while len(others) < AT_ONCE - 1:
            other = str(stack.enter_context(domain_id()))
            if other != own:
                others.append(other)
        yield [own, *others]
