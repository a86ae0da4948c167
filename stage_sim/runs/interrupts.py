"""Ctrl-C and SIGTERM for the programs that must say something on the way out.

The wanderer and the teleop publish a zero twist when they stop, the launch scripts print their summaries,
``stage_sim run`` finalises its bag; rclpy's own signal handlers would shut the context down first and leave
the robot on its last command, and a KeyboardInterrupt raised in the middle of a step can land inside a
compiled kernel's callback (numba reports it as a SystemError) or inside a lock. These programs use one of
these instead (the ROS ones init rclpy without its handlers). ROS-free: the core-only CLI uses them too.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator


@contextlib.contextmanager
def sigterm_interrupts() -> Iterator[None]:
    """Let SIGTERM raise KeyboardInterrupt like SIGINT while the block runs."""
    previous = signal.signal(signal.SIGTERM, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextlib.contextmanager
def stop_requests() -> Iterator[threading.Event]:
    """While the block runs, SIGINT and SIGTERM set the yielded event instead of raising.

    For loops that step or spin in the main thread: they check the event between steps (or spins) and stop
    cleanly, whereas a KeyboardInterrupt raised inside one of rclpy's C++ calls surfaces as a RuntimeError
    and one inside a numba kernel's callback as a SystemError.
    """
    requested = threading.Event()
    previous = {number: signal.signal(number, lambda *_: requested.set()) for number in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield requested
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
