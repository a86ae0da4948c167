"""``teleop [--ros-args ...]``: drive a robot from the keyboard like ros2/teleop_twist_keyboard 2.4.x.

Each key press publishes one ``geometry_msgs/Twist`` (``TwistStamped`` with ``stamped:=true``) on the
relative topic ``cmd_vel``; nothing repeats while idle. Ctrl-C (``\\x03`` in raw mode), end of input,
SIGINT and SIGTERM all end with a zero twist and the terminal restored, so a robot never keeps the last
command. The key source is injectable (:class:`KeyReader` takes any stream or descriptor) for tests.
"""

from __future__ import annotations

import argparse
import codecs
import io
import os
import select
import sys
import termios
import threading
import tty
from dataclasses import dataclass
from typing import IO, Any, TextIO

# Project rule: discovery stays on loopback unless the user chose otherwise (set before rclpy loads).
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import rclpy
from geometry_msgs.msg import Twist, TwistStamped
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.executors import SingleThreadedExecutor
from rclpy.logging import get_logger
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args

from stage_sim.interface.topics import CMD_VEL
from stage_sim.ros.qos import qos_profile
from stage_sim.runs.interrupts import sigterm_interrupts

NODE_NAME = "teleop_twist_keyboard"  # the original's name, so its parameter files apply unchanged
QUIT_KEY = "\x03"
STOP = (0, 0, 0, 0)
# Key -> (x, y, z, th) direction; x/y/z scale with speed, th with turn. Any other key stops.
MOVE_BINDINGS: dict[str, tuple[int, int, int, int]] = {
    "u": (1, 0, 0, 1), "i": (1, 0, 0, 0), "o": (1, 0, 0, -1),
    "j": (0, 0, 0, 1), "l": (0, 0, 0, -1),
    "m": (-1, 0, 0, -1), ",": (-1, 0, 0, 0), ".": (-1, 0, 0, 1),
    "U": (1, 1, 0, 0), "I": (1, 0, 0, 0), "O": (1, -1, 0, 0),
    "J": (0, 1, 0, 0), "L": (0, -1, 0, 0),
    "M": (-1, 1, 0, 0), "<": (-1, 0, 0, 0), ">": (-1, -1, 0, 0),
    "t": (0, 0, 1, 0), "b": (0, 0, -1, 0),
}
# Key -> (speed factor, turn factor).
SPEED_BINDINGS: dict[str, tuple[float, float]] = {
    "q": (1.1, 1.1), "z": (0.9, 0.9),
    "w": (1.1, 1.0), "x": (0.9, 1.0),
    "e": (1.0, 1.1), "c": (1.0, 0.9),
}
HELP_EVERY = 15  # speed changes between re-prints of the help, as in the original
HELP = """
stage_sim teleop: reads single key presses and publishes them as a Twist on cmd_vel.
Laid out for a US keyboard.
---------------------------
Drive and turn:
   u    i    o
   j    k    l
   m    ,    .

Strafe (holonomic robots) with shift held:
---------------------------
   U    I    O
   J    K    L
   M    <    >

t : rise (+z)
b : sink (-z)

any other key : stop

q/z : raise/lower both speeds by 10%
w/x : raise/lower the linear speed only by 10%
e/c : raise/lower the angular speed only by 10%

CTRL-C to quit
"""


def status_line(speed: float, turn: float) -> str:
    """The original's speed report, byte for byte (scripts scrape it)."""
    return f"currently:\tspeed {speed}\tturn {turn} "


@dataclass
class TeleopState:
    """What the keys have set so far: the direction, both speeds and the speed-change counter."""

    speed: float = 0.5
    turn: float = 1.0
    direction: tuple[int, int, int, int] = STOP
    speed_changes: int = 0  # modulo HELP_EVERY

    def press(self, key: str) -> list[str]:
        """Apply one key; returns what to print (after a speed key: the status, every 15th also the help)."""
        if key not in SPEED_BINDINGS:
            self.direction = MOVE_BINDINGS.get(key, STOP)
            return []
        speed_factor, turn_factor = SPEED_BINDINGS[key]
        self.speed *= speed_factor
        self.turn *= turn_factor
        self.speed_changes = (self.speed_changes + 1) % HELP_EVERY
        return [status_line(self.speed, self.turn)] + ([HELP] if self.speed_changes == 0 else [])

    def velocity(self) -> tuple[float, float, float, float]:
        """(linear x, y, z, angular z) for the current direction at the current speeds."""
        x, y, z, th = self.direction
        return x * self.speed, y * self.speed, z * self.speed, th * self.turn


class KeyReader:
    """Single key presses from a terminal (in raw mode while open) or from any other stream or descriptor.

    A terminal gets raw mode once for the whole session, with output processing left on so ``print`` still
    starts lines at the left edge; the settings saved on entry come back on exit. Non-terminals (pipes,
    files, ``io.StringIO``) are read as they are, without termios.
    """

    def __init__(self, source: int | IO[Any]) -> None:
        self._stream: IO[Any] | None = None if isinstance(source, int) else source
        self._fd = source if isinstance(source, int) else _fileno(source)
        self._decoder = codecs.getincrementaldecoder("utf-8")(errors="replace")
        self._pending = ""  # decoded characters beyond the one returned (only after invalid UTF-8)
        self._saved: list[Any] | None = None

    def __enter__(self) -> KeyReader:
        if self._fd is not None and os.isatty(self._fd):
            self._saved = termios.tcgetattr(self._fd)
            tty.setraw(self._fd)  # TCSAFLUSH: keys typed before the banner must not move the robot
            attrs = termios.tcgetattr(self._fd)
            attrs[tty.OFLAG] |= termios.OPOST
            termios.tcsetattr(self._fd, termios.TCSANOW, attrs)
        return self

    def __exit__(self, *exc_info: object) -> None:
        if self._saved is not None:
            termios.tcsetattr(self._fd, termios.TCSADRAIN, self._saved)
            self._saved = None

    def read_key(self, timeout_s: float | None = None) -> str | None:
        """The next key (one character); None if none came within ``timeout_s``, ``""`` at end of input.

        Streams without a descriptor cannot be polled and block regardless of the timeout.
        """
        while not self._pending:
            if self._fd is None:
                data = self._stream.read(1)  # type: ignore[union-attr]
            elif select.select([self._fd], [], [], timeout_s)[0]:
                data = os.read(self._fd, 1)
            else:
                return None
            if not data:
                return ""
            self._pending = data if isinstance(data, str) else self._decoder.decode(data)
        key, self._pending = self._pending[0], self._pending[1:]
        return key


def _fileno(stream: IO[Any]) -> int | None:
    """The stream's descriptor, or None for in-memory streams."""
    try:
        return stream.fileno()
    except (AttributeError, ValueError, io.UnsupportedOperation):
        return None


def _read_only(description: str) -> ParameterDescriptor:
    return ParameterDescriptor(description=description, read_only=True)


class TeleopTwistKeyboard(Node):
    """Publishes one twist per key press on ``cmd_vel``; ``kwargs`` go to :class:`rclpy.node.Node`.

    Raises ValueError (after destroying itself) when ``frame_id`` is set without ``stamped``, since a
    plain Twist has nowhere to carry it.
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(NODE_NAME, **kwargs)
        self.stamped = bool(self.declare_parameter(
            "stamped", False, _read_only("publish TwistStamped instead of Twist")).value)
        self.frame_id = str(self.declare_parameter(
            "frame_id", "", _read_only("header.frame_id of TwistStamped (needs stamped:=true)")).value)
        speed = float(self.declare_parameter("speed", 0.5, _read_only("initial linear speed, m/s")).value)
        turn = float(self.declare_parameter("turn", 1.0, _read_only("initial angular speed, rad/s")).value)
        if self.frame_id and not self.stamped:
            self.destroy_node()
            raise ValueError("'frame_id' can only be set when 'stamped' is true")
        self.state = TeleopState(speed=speed, turn=turn)
        self.publisher = self.create_publisher(
            TwistStamped if self.stamped else Twist, CMD_VEL.name, qos_profile(CMD_VEL.qos))

    def publish_velocity(self, velocity: tuple[float, float, float, float]) -> None:
        """Publish (linear x, y, z, angular z), stamped with the node clock when ``stamped``."""
        msg: Twist | TwistStamped = TwistStamped() if self.stamped else Twist()
        twist = msg.twist if isinstance(msg, TwistStamped) else msg
        if isinstance(msg, TwistStamped):
            msg.header.stamp = self.get_clock().now().to_msg()
            msg.header.frame_id = self.frame_id
        twist.linear.x, twist.linear.y, twist.linear.z, twist.angular.z = velocity
        self.publisher.publish(msg)

    def run(self, keys: KeyReader, out: TextIO | None = None, poll_s: float = 0.1) -> None:
        """Print the help, then publish a twist per key until Ctrl-C, end of input or shutdown.

        Always publishes a zero twist on the way out while the context still allows it. ``poll_s`` bounds
        how late a shutdown of the context is noticed.
        """
        out = sys.stdout if out is None else out
        print(HELP, file=out)
        print(status_line(self.state.speed, self.state.turn), file=out, flush=True)
        try:
            while self.context.ok():
                key = keys.read_key(poll_s)
                if key is None:
                    continue
                if key in (QUIT_KEY, ""):
                    break
                for line in self.state.press(key):
                    print(line, file=out, flush=True)
                self.publish_velocity(self.state.velocity())
        finally:
            if self.context.ok():
                self.publish_velocity((0.0, 0.0, 0.0, 0.0))


def parse_args(argv: list[str]) -> argparse.Namespace:
    """``--help`` (and a clear error for anything else that is not a ROS argument)."""
    parser = argparse.ArgumentParser(
        prog="teleop", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Drive a robot from the keyboard, as teleop_twist_keyboard does: each key press publishes "
        "one Twist on cmd_vel (relative: --ros-args -r __ns:=/robot_0 picks a robot). Needs a terminal.\n" + HELP,
        epilog="parameters (--ros-args -p NAME:=VALUE): speed (m/s), turn (rad/s), stamped (TwistStamped), "
        "frame_id (with stamped)")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Run the teleop on stdin until Ctrl-C; 0 on a normal quit, 2 on bad parameters or without a terminal."""
    argv = list(sys.argv if argv is None else argv)
    parse_args(remove_ros_args(argv)[1:])
    if not sys.stdin.isatty():
        print("teleop: needs a terminal to read single key presses from (standard input is not one); run it in "
              "a terminal of its own", file=sys.stderr)
        return 2
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    node: TeleopTwistKeyboard | None = None
    executor = SingleThreadedExecutor()
    spinner = threading.Thread(target=executor.spin, name="teleop-spin", daemon=True)
    try:
        with sigterm_interrupts():
            try:
                node = TeleopTwistKeyboard()
            except ValueError as error:
                get_logger(NODE_NAME).error(str(error))
                return 2
            executor.add_node(node)
            spinner.start()  # services parameters and the sim clock while main blocks on the keyboard
            with KeyReader(sys.stdin) as keys:
                node.run(keys)
        return 0
    except KeyboardInterrupt:
        return 0
    finally:
        executor.shutdown()
        if spinner.is_alive():
            spinner.join()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
