"""The ``stageros`` node: a thin rclpy layer that steps a :class:`~stage_sim.sim.simulation.Simulation`.

Per robot it subscribes ``cmd_vel`` and publishes ``odom``, ``base_pose_ground_truth``, ``base_scan[_k]``
and ``stall``; for the world it publishes ``/clock`` (one per step, never 0), ``/tf`` (odom →
base_footprint every step), ``/tf_static`` (one latched message with every fixed frame) and, on request,
``/map``; it serves ``reset_positions``. Every stamp is sim time. A steady wall timer wakes the node every
``interval_sim / speedup`` (``speedup <= 0``: at every executor round), never the clock the node publishes;
the run's :class:`~stage_sim.runs.pacing.Pacer` then decides which steps are due, as it does for every
entry point (as fast as possible: steps back to back for FAST_BATCH_S of wall time, then callbacks are
serviced).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from geometry_msgs.msg import Twist
from rclpy.clock import Clock, ClockType
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.timer import Timer
from std_srvs.srv import Empty

from stage_sim.interface import qos, topics
from stage_sim.interface.names import RobotNames, robot_names
from stage_sim.interface.topics import Endpoint, Fill, Scope, Timing, Topic
from stage_sim.maps.tiles import WorldTooLargeError
from stage_sim.ros import conversions
from stage_sim.ros.parameters import ParameterSpec, declare_parameters
from stage_sim.ros.qos import qos_profile
from stage_sim.ros.rival_publishers import RivalPublishers
from stage_sim.ros.topic_messages import TOPIC_MESSAGES, message_class
from stage_sim.runs.pacing import WATCHDOG_S, Pacer, run_end, run_speedup, threads_for_run
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world

# Commands beyond this magnitude (m/s or rad/s) are treated as garbage, not as "go very fast".
ABSURD_COMMAND = 1e3
# At most one warning per robot in this many wall seconds about rejected commands.
WARNING_THROTTLE_S = 5.0

# rclpy gives every publisher and subscription default QoS-event handlers, each a waitable the executor
# re-adds to its wait set before every callback: with hundreds of per-robot endpoints that cost more than
# the simulation step. Per-robot endpoints go without them; the world-wide ones keep the default warnings.
NO_PUB_EVENTS = PublisherEventCallbacks(use_default_callbacks=False)
# Timer wake-ups per step period. One, and a wake-up a little early (timer jitter) finds no step due and the
# next steps one period late; a late node catching up with back-to-back callbacks (a guard condition) starved
# the subscriptions, so commands waited while the watchdog stopped the robot. Two let it catch up a step per
# half period, the executor's other work in between.
WAKES_PER_STEP = 2
NO_SUB_EVENTS = SubscriptionEventCallbacks(use_default_callbacks=False)


@dataclass
class _Channel:
    """One published topic: its filler and, per endpoint, the publisher and the message built once for it."""

    topic: Topic
    fill: Fill
    outlets: list[tuple[Publisher, Any, Endpoint]]


class StageRos(Node):
    """Publishes a Stage world's robots on the ROS graph the way stageros does."""

    def __init__(
        self, world: str | Path | None = None, *, speedup: float | None = None, seed: int | None = None,
        use_model_names: bool | None = None, node_name: str = "stageros", autostep: bool = True,
        kernels: str | None = None, threads: int | None = None, duration: float | None = None,
        recording: bool = False, **kwargs,
    ) -> None:
        """Load the world and advertise everything; ``autostep=False`` leaves stepping to the caller
        (:meth:`step_once`), for tests and programs that drive the simulation themselves. ``threads``
        defaults to 1 in real time and to all cores with ``speedup <= 0`` (all but one when ``recording`` a
        bag: :func:`~stage_sim.runs.pacing.threads_for_run`). The run ends at the world's
        ``quit_time`` or after ``duration`` sim seconds, whichever comes first."""
        super().__init__(node_name, **kwargs)
        (world_param,) = declare_parameters(self, [ParameterSpec(
            "world_file", str(world) if world is not None else "", "the .world file, or a bundled world's name")
        ]).values()
        if not world_param:
            raise ValueError("no world given: pass WORLD on the command line or set the 'world_file' parameter")
        description = load_world(world_param)
        self.world_path = description.path
        params = declare_parameters(self, [
            ParameterSpec("speedup", float(run_speedup(speedup, description.settings.speedup)),
                          "sim seconds per wall second (<= 0: as fast as possible)", on_change=self.set_speedup),
            ParameterSpec("seed", -1 if seed is None else seed, "seed of the odometry errors and noise (-1: random)"),
            ParameterSpec("base_watchdog_timeout", WATCHDOG_S, "sim seconds a command lasts without a new one",
                          on_change=lambda timeout: setattr(self.sim, "watchdog_timeout", timeout)),
            ParameterSpec("use_model_names", bool(use_model_names), "name topics and frames after the models"),
            ParameterSpec("publish_map", False, "publish the static world on /map (latched)"),
            ParameterSpec("use_stamped_velocity", False, "cmd_vel is geometry_msgs/TwistStamped"),
        ])
        speedup, seed_value = params["speedup"], params["seed"]
        model_names, stamped = params["use_model_names"], params["use_stamped_velocity"]
        self.publish_map = params["publish_map"]

        self.sim = Simulation(description, seed=None if seed_value < 0 else seed_value,
                              watchdog_timeout=params["base_watchdog_timeout"], kernels=kernels,
                              threads=threads_for_run(threads, speedup, recording))
        for warning in self.sim.warnings:
            self.get_logger().warning(str(warning))
        robots = self.sim.robots
        self.names: list[RobotNames] = [
            robot_names(r.index, r.name, len(robots), len(r.rangers), model_names) for r in robots
        ]
        self._create_interfaces(stamped)
        self._last_warning = [-math.inf] * len(robots)
        self.quit_time = description.settings.quit_time
        self.pacer = Pacer(self.sim.interval, speedup, lambda: self.sim.sim_time, run_end(self.quit_time, duration))
        self.finished = False
        self._step_listeners: list[Callable[[], None]] = []
        self.autostep = autostep
        self._timer = self._step_timer(autostep)
        self._publish_static()
        self.rivals = RivalPublishers(self, [topics.CLOCK.name], [
            t for n in self.names for t in (*topics.ODOM.names_on(n), *topics.SCAN.names_on(n)[:1])])
        self.get_logger().info(
            f"{self.world_path.name}: {len(robots)} robot(s), interval_sim {self.sim.interval * 1000:g} ms, "
            f"speedup {speedup:g}" + (" (as fast as possible)" if speedup <= 0 else ""))

    # -- set-up --------------------------------------------------------------------------------------------

    def _create_interfaces(self, stamped: bool) -> None:
        """A publisher per endpoint of every published topic, its message built once (publishing serialises,
        so refilling is safe), a subscription per endpoint of every subscribed topic, and the reset service.
        Publishers come first: Fast DDS creates an endpoint in time growing with the participant's endpoints,
        and on hospital.world (1000 robots) the writers first, then the readers, take 3.5 s of CPU, not 4.2 s."""
        handlers: dict[Topic, Callable[[int, Any], None]] = {
            topics.CMD_VEL: self.on_command,
            topics.CMD_VEL_STAMPED: lambda robot, msg: self.on_command(robot, msg.twist),
        }
        self.publishers_by_name: dict[str, Publisher] = {}
        self._channels: list[_Channel] = []
        for topic in topics.published(self.publish_map):
            outlets = []
            for endpoint in topics.endpoints(topic, self.names):
                publisher = self.create_publisher(
                    message_class(topic), endpoint.name, qos_profile(topic.qos),
                    event_callbacks=None if topic.scope is Scope.WORLD else NO_PUB_EVENTS)
                self.publishers_by_name[endpoint.name] = publisher
                outlets.append((publisher, TOPIC_MESSAGES[topic].build(endpoint, self.sim, self.names), endpoint))
            self._channels.append(_Channel(topic, TOPIC_MESSAGES[topic].fill, outlets))
        for topic in topics.subscribed(stamped):
            for endpoint in topics.endpoints(topic, self.names):
                self.create_subscription(
                    message_class(topic), endpoint.name, lambda msg, i=endpoint.robot, h=handlers[topic]: h(i, msg),
                    qos_profile(topic.qos), event_callbacks=NO_SUB_EVENTS)
        self._stepped = [channel for channel in self._channels if channel.topic.timing is not Timing.START]
        self.create_service(Empty, topics.RESET_POSITIONS, self.on_reset,
                            qos_profile=qos_profile(qos.EVERY_REQUEST))

    def destroy_node(self) -> None:
        """Destroy the subscriptions before the publishers: Fast DDS takes time in proportion to the
        participant's readers to delete each writer (1000 robots: 18 s of CPU the other way round)."""
        for subscription in list(self.subscriptions):
            self.destroy_subscription(subscription)
        super().destroy_node()

    def _step_timer(self, start: bool) -> Timer:
        """The steady wall timer that wakes the node WAKES_PER_STEP times per step period (0: at every executor
        round): a node woken late catches up a step per wake-up, with the executor's other callbacks (commands,
        which the watchdog counts in sim time) in between."""
        return self.create_timer(self.pacer.period / WAKES_PER_STEP, self._step_due,
                                 clock=Clock(clock_type=ClockType.STEADY_TIME), autostart=start)

    def _step_due(self) -> None:
        """The steps the pacer says are due now."""
        for _ in self.pacer.steps():
            self.step_once()

    def _publish_static(self) -> None:
        """The latched topics, once: one /tf_static message with every robot's fixed frames (and /map if asked)."""
        time = conversions.stamp(self.sim.sim_time_us)
        for channel in self._channels:
            if channel.topic.timing is not Timing.START:
                continue
            try:
                values = channel.topic.values(self.sim, self.names)
            except WorldTooLargeError as error:  # the simulation runs on; only the picture is refused
                self.get_logger().warning(f"not publishing {channel.topic.name}: {error}")
                continue
            for publisher, msg, endpoint in channel.outlets:
                publisher.publish(channel.fill(msg, values, endpoint, time))

    # -- callbacks -----------------------------------------------------------------------------------------

    def add_step_listener(self, listener: Callable[[], None]) -> None:
        """Call ``listener()`` after every step (after publishing): recorders, statistics, lockstep drivers."""
        self._step_listeners.append(listener)

    def on_command(self, robot: int, twist: Twist) -> None:
        """Accept a finite, sane command; reject anything else with a throttled warning."""
        values = (twist.linear.x, twist.linear.y, twist.angular.z)
        if all(math.isfinite(v) and abs(v) <= ABSURD_COMMAND for v in values):
            self.sim.set_velocity(robot, *values)
            return
        now = self.get_clock().now().nanoseconds / 1e9
        if now - self._last_warning[robot] >= WARNING_THROTTLE_S:
            self._last_warning[robot] = now
            self.get_logger().warning(
                f"{self.names[robot].topic(topics.CMD_VEL.name)}: rejected command {values} (not finite or above "
                f"{ABSURD_COMMAND:g}); keeping the previous one")

    def on_reset(self, request: Empty.Request, response: Empty.Response) -> Empty.Response:
        """reset_positions: executor callbacks never overlap the step, so this lands between steps."""
        self.sim.reset_positions()
        return response

    def start_stepping(self) -> None:
        """Step on the node's own timer from now on (for callers that built it with ``autostep=False``)."""
        self.autostep = True
        self.set_paused(self.pacer.paused)

    def set_paused(self, paused: bool) -> None:
        """Stop or resume stepping (the browser view's pause): sim time and /clock stand still meanwhile."""
        self.pacer.set_paused(paused)
        if self.autostep and not self.finished:
            if paused:
                self._timer.cancel()
            else:
                self._timer.reset()

    def set_speedup(self, speedup: float) -> None:
        """Step at a new real-time factor from now on (``<= 0``: as fast as possible)."""
        self.pacer.set_speedup(speedup)
        self.destroy_timer(self._timer)
        self._timer = self._step_timer(self.autostep and not self.pacer.paused and not self.finished)

    def step_once(self) -> None:
        """One simulation step and everything it publishes (none while paused)."""
        if self.finished or self.pacer.paused:
            return
        self.sim.step()
        self._publish_step()
        for listener in self._step_listeners:
            listener()
        if self.pacer.finished():
            self.finished = True
            self._timer.cancel()
            reason = "quit_time" if self.pacer.end == self.quit_time else "duration"
            self.get_logger().info(f"{reason} {self.pacer.end:g} s reached")

    def _publish_step(self) -> None:
        """Every per-step topic, in the registry's order. A message nobody has subscribed to is neither filled
        nor serialised (asking DDS costs ~1.5 µs, a publish 15-80 µs): with a hundred robots most topics have no
        reader, and lockstep runs go 2x faster."""
        sim, names = self.sim, self.names
        time = conversions.stamp(sim.sim_time_us)
        for channel in self._stepped:
            values = channel.topic.values(sim, names)
            fill = channel.fill
            for publisher, msg, endpoint in channel.outlets:
                if publisher.get_subscription_count():
                    filled = fill(msg, values, endpoint, time)
                    if filled is not None:
                        publisher.publish(filled)
