"""The browser view of ``stageros`` and the launch scripts: on by default, as Stage opens its window; ``-g`` off.

A page's commands take the node's own paths: a key press is a ``cmd_vel`` message handed to
:meth:`StageRos.on_command` (same checks, same watchdog), the reset button calls the ``reset_positions``
handler, pause and speed act on the node's step timer. The view is serviced by a steady 30 Hz timer on the
node, so it runs on the executor between steps like every other callback.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Iterator
from typing import TYPE_CHECKING

from geometry_msgs.msg import Twist
from rclpy.clock import Clock, ClockType
from std_srvs.srv import Empty

from stage_sim.view.options import add_view_arguments, view_settings

if TYPE_CHECKING:
    from stage_sim.ros.stageros import StageRos
    from stage_sim.view.live import LiveView

SERVICE_PERIOD_S = 1.0 / 30.0


def add_view_options(parser: argparse.ArgumentParser) -> None:
    """``-g`` (Stage's "no GUI": no view) and the view's ``--view-*`` options."""
    parser.add_argument("-g", action="store_true", dest="no_view",
                        help="no GUI: do not serve the browser view (tests, benchmarks, headless runs)")
    add_view_arguments(parser)


class RosControls:
    """The view's controls as the ``stageros`` node's own inputs."""

    def __init__(self, stage: StageRos) -> None:
        self.stage = stage
        self.pacer = stage.pacer

    def drive(self, robot: int, vx: float, vy: float, va: float) -> None:
        twist = Twist()
        twist.linear.x, twist.linear.y, twist.angular.z = vx, vy, va
        self.stage.on_command(robot, twist)

    def reset_positions(self) -> None:
        self.stage.on_reset(Empty.Request(), Empty.Response())

    def set_paused(self, paused: bool) -> None:
        self.stage.set_paused(paused)

    def set_speedup(self, speedup: float) -> None:
        """Only a node that paces itself changes speed (a lockstep session keeps its own pace)."""
        if self.stage.autostep:
            self.stage.set_speedup(speedup)


@contextlib.contextmanager
def viewing(stage: StageRos, args: argparse.Namespace) -> Iterator[LiveView | None]:
    """Serve ``stage``'s view while the block runs (prints ``view: URL``); yields None with ``-g``."""
    if args.no_view:
        yield None
        return
    try:
        from stage_sim.view.live import LiveView
    except ImportError as error:  # a ROS install whose rosdep did not bring aiohttp: run on without the view
        print(f"view: not served: the Python package '{error.name or error}' is missing (pip install aiohttp); "
              "-g turns the view off", file=sys.stderr, flush=True)
        yield None
        return

    names = [name.label or robot.name or "robot"
             for name, robot in zip(stage.names, stage.sim.robots, strict=True)]
    view = LiveView(stage.sim, RosControls(stage), view_settings(args), names)
    try:
        view.start()
    except OSError as error:  # every port taken, an unknown host: the simulation runs on without its view
        print(f"view: not served: {error}", file=sys.stderr, flush=True)
        yield None
        return
    timer = stage.create_timer(SERVICE_PERIOD_S, view.service, clock=Clock(clock_type=ClockType.STEADY_TIME))
    try:
        yield view
    finally:
        stage.destroy_timer(timer)
        view.close()
