"""Child processes for the corpus tests: a memory limit, a wall timeout and the CPU time they used.

Every world runs in a child whose address space is capped, so that a world that would grow without
bound (as Stage's SFU.world and large.world did before the sparse world) fails there, never takes the
machine down, and never leaves pytest itself short of memory.
"""

from __future__ import annotations

import queue
import re
import resource
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

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


def run_limited(command: list[str], ready: re.Pattern[str] | None = None) -> ChildRun:
    """Run ``command`` with capped memory until it exits (or the wall timeout); with ``ready``, interrupt
    it (Ctrl-C) as soon as a line of its stderr matches, as a user stops a simulator that has come up."""
    cpu_before = _children_cpu()
    if ready is None:
        try:
            done = subprocess.run(command, capture_output=True, text=True, preexec_fn=_cap_memory, cwd=REPO,
                                  timeout=WALL_TIMEOUT_S)
        except subprocess.TimeoutExpired as expired:
            return ChildRun(None, str(expired.stdout or ""), str(expired.stderr or ""), _children_cpu() - cpu_before)
        return ChildRun(done.returncode, done.stdout, done.stderr, _children_cpu() - cpu_before)
    child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                             preexec_fn=_cap_memory, cwd=REPO)
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
