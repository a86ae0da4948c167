"""The keyboard teleop: keys fed through a pseudo-terminal, twists checked on a subscriber.

In-process tests run :meth:`TeleopTwistKeyboard.run` in a thread reading a pty slave in raw mode while the
test thread writes keys to the master and spins the subscriber; one test drives the real ``main`` in a
subprocess whose stdin is a pty.
"""

from __future__ import annotations

import io
import os
import pty
import subprocess
import sys
import termios
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from geometry_msgs.msg import Twist, TwistStamped
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter

from stage_sim.ros.teleop import HELP, KeyReader, TeleopState, TeleopTwistKeyboard, main, status_line
from tests.ros.helpers import spin_until

REPO = Path(__file__).resolve().parents[2]
ZERO = (0.0, 0.0, 0.0, 0.0)


def velocity(msg: Twist | TwistStamped) -> tuple[float, float, float, float]:
    """(linear x, y, z, angular z) of a received message; the other angular axes must stay zero."""
    twist = msg.twist if isinstance(msg, TwistStamped) else msg
    assert (twist.angular.x, twist.angular.y) == (0.0, 0.0)
    return twist.linear.x, twist.linear.y, twist.linear.z, twist.angular.z


def is_raw(fd: int) -> bool:
    """Whether the terminal has line editing and echo off, i.e. the teleop owns it."""
    return not termios.tcgetattr(fd)[3] & (termios.ICANON | termios.ECHO)


class PtyTeleop:
    """An in-process teleop reading keys from a pty slave in a thread, plus a subscriber on ``cmd_vel``."""

    def __init__(self, context: Context, executor: SingleThreadedExecutor, overrides: list[Parameter]) -> None:
        self.executor = executor
        self.master, self.slave = pty.openpty()
        self.attrs_before = termios.tcgetattr(self.slave)
        self.node = TeleopTwistKeyboard(context=context, parameter_overrides=overrides)
        listener = Node("teleop_listener", context=context)
        executor.add_node(self.node)
        executor.add_node(listener)
        self.received: list[Twist | TwistStamped] = []
        msg_type = TwistStamped if self.node.stamped else Twist
        listener.create_subscription(msg_type, "cmd_vel", self.received.append, 100)
        assert spin_until(executor, lambda: self.node.publisher.get_subscription_count() > 0)
        self.out = io.StringIO()
        self.keys = KeyReader(self.slave)
        self.keys.__enter__()  # raw mode before any key is written, so none is echoed or line-buffered
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        try:
            self.node.run(self.keys, out=self.out, poll_s=0.05)
        finally:
            self.keys.__exit__(None, None, None)

    def press(self, keys: str) -> list[tuple[float, float, float, float]]:
        """Type ``keys`` and return the velocities published for them (one message per key)."""
        start = len(self.received)
        os.write(self.master, keys.encode())
        assert spin_until(self.executor, lambda: len(self.received) >= start + len(keys)), self.received[start:]
        return [velocity(m) for m in self.received[start:]]

    def quit(self) -> None:
        """Press Ctrl-C and wait for the run loop to end."""
        os.write(self.master, b"\x03")
        self.thread.join(timeout=5.0)
        assert not self.thread.is_alive()

    def close(self) -> None:
        if self.thread.is_alive():
            self.quit()
        os.close(self.master)
        os.close(self.slave)


@pytest.fixture
def teleop_factory(ros_context: Context, executor: SingleThreadedExecutor) -> Iterator:
    """Builds a :class:`PtyTeleop` with optional parameter overrides; quits and closes it afterwards."""
    made: list[PtyTeleop] = []

    def make(**params: object) -> PtyTeleop:
        made.append(PtyTeleop(ros_context, executor, [Parameter(k, value=v) for k, v in params.items()]))
        return made[-1]

    yield make
    for teleop in made:
        teleop.close()


@pytest.fixture
def teleop(teleop_factory) -> PtyTeleop:
    return teleop_factory()


DIFF_DRIVE = {
    "u": (0.5, 0.0, 0.0, 1.0), "i": (0.5, 0.0, 0.0, 0.0), "o": (0.5, 0.0, 0.0, -1.0),
    "j": (0.0, 0.0, 0.0, 1.0), "l": (0.0, 0.0, 0.0, -1.0),
    "m": (-0.5, 0.0, 0.0, -1.0), ",": (-0.5, 0.0, 0.0, 0.0), ".": (-0.5, 0.0, 0.0, 1.0),
}
HOLONOMIC = {
    "U": (0.5, 0.5, 0.0, 0.0), "I": (0.5, 0.0, 0.0, 0.0), "O": (0.5, -0.5, 0.0, 0.0),
    "J": (0.0, 0.5, 0.0, 0.0), "L": (0.0, -0.5, 0.0, 0.0),
    "M": (-0.5, 0.5, 0.0, 0.0), "<": (-0.5, 0.0, 0.0, 0.0), ">": (-0.5, -0.5, 0.0, 0.0),
}
VERTICAL = {"t": (0.0, 0.0, 0.5, 0.0), "b": (0.0, 0.0, -0.5, 0.0)}


@pytest.mark.parametrize("bindings", [DIFF_DRIVE, HOLONOMIC, VERTICAL], ids=["diff-drive", "holonomic", "vertical"])
def test_each_move_key_publishes_its_twist(teleop: PtyTeleop, bindings: dict) -> None:
    for key, expected in bindings.items():
        assert teleop.press(key) == [expected], key


def test_k_and_unknown_keys_stop(teleop: PtyTeleop) -> None:
    assert teleop.press("ik") == [DIFF_DRIVE["i"], ZERO]
    assert teleop.press("ua") == [DIFF_DRIVE["u"], ZERO]
    assert teleop.press("j\x1b") == [DIFF_DRIVE["j"], ZERO]  # escape: first byte of an arrow key
    assert teleop.press("oé") == [DIFF_DRIVE["o"], ZERO]  # two UTF-8 bytes, one key, one twist


def test_one_twist_per_key_press_nothing_while_idle(teleop: PtyTeleop) -> None:
    teleop.press("i")
    deadline = time.monotonic() + 0.3
    while time.monotonic() < deadline:
        teleop.executor.spin_once(timeout_sec=0.02)
    assert len(teleop.received) == 1


def test_speed_keys_scale_republish_and_report(teleop: PtyTeleop) -> None:
    assert teleop.press("u") == [(0.5, 0.0, 0.0, 1.0)]
    assert teleop.press("q") == [(pytest.approx(0.55), 0.0, 0.0, pytest.approx(1.1))]
    assert status_line(0.55, 1.1) == "currently:\tspeed 0.55\tturn 1.1 "
    assert "currently:\tspeed 0.55\tturn 1.1 \n" in teleop.out.getvalue()
    speed, turn = 0.55, 1.1
    for key, (speed_factor, turn_factor) in {"z": (0.9, 0.9), "w": (1.1, 1), "x": (0.9, 1),
                                              "e": (1, 1.1), "c": (1, 0.9)}.items():
        speed, turn = speed * speed_factor, turn * turn_factor
        assert teleop.press(key) == [(pytest.approx(speed), 0.0, 0.0, pytest.approx(turn))], key
        assert status_line(speed, turn) in teleop.out.getvalue(), key
    assert teleop.press("i") == [(pytest.approx(speed), 0.0, 0.0, 0.0)]
    assert teleop.press("k") == [ZERO]
    assert teleop.press("e") == [ZERO]  # a speed key re-publishes the current direction, which is stop


def test_help_is_printed_first_and_again_every_15_speed_changes(teleop: PtyTeleop) -> None:
    teleop.press("w" * 14)
    assert teleop.out.getvalue().count(HELP) == 1
    teleop.press("w")
    assert teleop.out.getvalue().count(HELP) == 2
    state = TeleopState()
    printed = [state.press("c") for _ in range(30)]
    assert [i for i, lines in enumerate(printed, 1) if HELP in lines] == [15, 30]
    assert all(lines[0].startswith("currently:") for lines in printed)


def test_ctrl_c_publishes_zero_and_restores_the_terminal(teleop: PtyTeleop) -> None:
    assert is_raw(teleop.slave)
    teleop.press("i")
    teleop.quit()
    assert spin_until(teleop.executor, lambda: len(teleop.received) == 2)
    assert velocity(teleop.received[-1]) == ZERO
    assert termios.tcgetattr(teleop.slave) == teleop.attrs_before


def test_speed_and_turn_parameters_are_read_only_start_values(teleop_factory) -> None:
    teleop = teleop_factory(speed=1.0, turn=2.0)
    assert teleop.press("u") == [(1.0, 0.0, 0.0, 2.0)]
    results = teleop.node.set_parameters([Parameter("speed", value=3.0), Parameter("stamped", value=True)])
    assert not any(r.successful for r in results)


def test_stamped_publishes_twist_stamped_in_frame(teleop_factory) -> None:
    teleop = teleop_factory(stamped=True, frame_id="base_link")
    assert teleop.press("i") == [(0.5, 0.0, 0.0, 0.0)]
    msg = teleop.received[0]
    assert isinstance(msg, TwistStamped)
    assert msg.header.frame_id == "base_link"
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) != (0, 0)


def test_frame_id_without_stamped_is_an_error(ros_context: Context, capfd, monkeypatch) -> None:
    with pytest.raises(ValueError, match="frame_id"):
        TeleopTwistKeyboard(context=ros_context, parameter_overrides=[Parameter("frame_id", value="base_link")])
    master, slave = pty.openpty()
    with os.fdopen(slave, "r") as terminal:
        monkeypatch.setattr(sys, "stdin", terminal)
        assert main(["teleop", "--ros-args", "-p", "frame_id:=base_link"]) == 2
    os.close(master)
    assert "'frame_id' can only be set when 'stamped' is true" in capfd.readouterr().err


def test_without_a_terminal_it_says_so_and_fails(capfd, monkeypatch) -> None:
    monkeypatch.setattr(sys, "stdin", io.StringIO("i"))
    assert main(["teleop"]) == 2
    assert "needs a terminal" in capfd.readouterr().err


def test_key_reader_on_plain_streams_uses_no_termios() -> None:
    with KeyReader(io.StringIO("iq")) as keys:
        assert [keys.read_key(), keys.read_key(), keys.read_key()] == ["i", "q", ""]
    with KeyReader(io.BytesIO("é,".encode())) as keys:
        assert [keys.read_key(), keys.read_key(), keys.read_key()] == ["é", ",", ""]
    read_end, write_end = os.pipe()
    try:
        with KeyReader(read_end) as keys:  # a pipe is no terminal: termios would raise here
            assert keys.read_key(timeout_s=0.01) is None
            os.write(write_end, b"\xffj")  # invalid UTF-8 becomes a key of its own (which stops)
            assert [keys.read_key(0.5), keys.read_key(0.5)] == ["\ufffd", "j"]
            os.close(write_end)
            assert keys.read_key(0.5) == ""
    finally:
        os.close(read_end)


@pytest.mark.slow
def test_main_in_a_subprocess_on_a_pty(ros_context: Context, executor: SingleThreadedExecutor) -> None:
    """The real entry point: raw mode on its stdin, ``i`` then Ctrl-C, exit 0, terminal as it was."""
    listener = Node("teleop_listener", context=ros_context)
    executor.add_node(listener)
    received: list[Twist] = []
    subscription = listener.create_subscription(Twist, "cmd_vel", received.append, 10)
    master, slave = pty.openpty()
    attrs_before = termios.tcgetattr(slave)
    proc = subprocess.Popen([sys.executable, "-m", "stage_sim.ros.teleop"], stdin=slave, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, cwd=REPO, env=dict(os.environ))
    try:
        assert spin_until(executor, lambda: subscription.get_publisher_count() > 0 and is_raw(slave), 15.0)
        # The reader side has matched; the writer side may match a moment later, and a message sent before
        # that is lost (volatile QoS). Pressing `i` again publishes the same twist, so retry a few times.
        for _ in range(5):
            os.write(master, b"i")
            if spin_until(executor, lambda: bool(received), 1.0):
                break
        assert [velocity(m) for m in received[:1]] == [(0.5, 0.0, 0.0, 0.0)]
        os.write(master, b"\x03")
        assert spin_until(executor, lambda: velocity(received[-1]) == ZERO, 5.0)
        out, err = proc.communicate(timeout=10.0)
        assert proc.returncode == 0, err.decode()
        assert b"currently:\tspeed 0.5\tturn 1.0 " in out
        assert termios.tcgetattr(slave) == attrs_before
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(master)
        os.close(slave)
