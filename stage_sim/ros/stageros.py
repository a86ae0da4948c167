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

from geometry_msgs.msg import TransformStamped, Twist, TwistStamped
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from nav_msgs.msg import Odometry
from rclpy.clock import Clock, ClockType
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.timer import Timer
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool
from std_srvs.srv import Empty
from tf2_msgs.msg import TFMessage

from stage_sim.bags import fields
from stage_sim.bags.names import RobotNames, robot_names
from stage_sim.maps.tiles import WorldTooLargeError
from stage_sim.ros import conversions
from stage_sim.ros.rival_publishers import RivalPublishers
from stage_sim.runs.pacing import WATCHDOG_S, Pacer, run_end, run_speedup, threads_for_run
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world

# Commands beyond this magnitude (m/s or rad/s) are treated as garbage, not as "go very fast".
ABSURD_COMMAND = 1e3
# At most one warning per robot in this many wall seconds about rejected commands.
WARNING_THROTTLE_S = 5.0

RELIABLE_10 = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
# rclpy gives every publisher and subscription default QoS-event handlers, each a waitable the executor
# re-adds to its wait set before every callback: with hundreds of per-robot endpoints that cost more than
# the simulation step. Per-robot endpoints go without them; the world-wide ones keep the default warnings.
NO_PUB_EVENTS = PublisherEventCallbacks(use_default_callbacks=False)
NO_SUB_EVENTS = SubscriptionEventCallbacks(use_default_callbacks=False)
TF_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
# Every request is a caller waiting for its answer: the default services queue (the last 10) drops requests
# whenever the executor lags (numba loading on its thread, a command flood), and those callers hang forever.
EVERY_REQUEST = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)


@dataclass
class _RobotMessages:
    """The messages one robot publishes every step, allocated once."""

    odom: Odometry
    truth: Odometry
    stall: Bool
    odom_tf: TransformStamped
    scans: list[LaserScan]


class StageRos(Node):
    """Publishes a Stage world's robots on the ROS graph the way stageros does."""

    def __init__(
        self, world: str | Path | None = None, *, speedup: float | None = None, seed: int | None = None,
        use_model_names: bool | None = None, node_name: str = "stageros", autostep: bool = True,
        kernels: str | None = None, threads: int | None = None, duration: float | None = None, **kwargs,
    ) -> None:
        """Load the world and advertise everything; ``autostep=False`` leaves stepping to the caller
        (:meth:`step_once`), for tests and programs that drive the simulation themselves. ``threads``
        defaults to 1 in real time and to all cores with ``speedup <= 0``. The run ends at the world's
        ``quit_time`` or after ``duration`` sim seconds, whichever comes first."""
        super().__init__(node_name, **kwargs)
        world_param = self.declare_parameter("world_file", str(world) if world is not None else "").value
        if not world_param:
            raise ValueError("no world given: pass WORLD on the command line or set the 'world_file' parameter")
        description = load_world(world_param)
        self.world_path = description.path
        speedup_default = run_speedup(speedup, description.settings.speedup)
        speedup = float(self.declare_parameter("speedup", float(speedup_default)).value)
        seed_value = int(self.declare_parameter("seed", -1 if seed is None else seed).value)
        watchdog = float(self.declare_parameter("base_watchdog_timeout", WATCHDOG_S).value)
        model_names = bool(self.declare_parameter("use_model_names", bool(use_model_names)).value)
        self.publish_map = bool(self.declare_parameter("publish_map", False).value)
        stamped = bool(self.declare_parameter("use_stamped_velocity", False).value)

        self.sim = Simulation(description, seed=None if seed_value < 0 else seed_value, watchdog_timeout=watchdog,
                              kernels=kernels, threads=threads_for_run(threads, speedup))
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
        self._catch_up = self.create_guard_condition(self._step_due)
        self._publish_static()
        self.rivals = RivalPublishers(self, ["/clock"], [t for n in self.names for t in (n.odom, *n.scans[:1])])
        self.get_logger().info(
            f"{self.world_path.name}: {len(robots)} robot(s), interval_sim {self.sim.interval * 1000:g} ms, "
            f"speedup {speedup:g}" + (" (as fast as possible)" if speedup <= 0 else ""))

    # -- set-up --------------------------------------------------------------------------------------------

    def _create_interfaces(self, stamped: bool) -> None:
        self.clock_pub = self.create_publisher(ClockMsg, "/clock", RELIABLE_10)
        self.tf_pub = self.create_publisher(TFMessage, "/tf", TF_QOS)
        self.tf_static_pub = self.create_publisher(TFMessage, "/tf_static", LATCHED)
        self.map_pub = self.create_publisher(OccupancyGridMsg, "/map", LATCHED) if self.publish_map else None
        self.odom_pubs, self.truth_pubs, self.stall_pubs, self.scan_pubs = [], [], [], []
        for index, names in enumerate(self.names):
            self.odom_pubs.append(self._robot_publisher(Odometry, names.odom))
            self.truth_pubs.append(self._robot_publisher(Odometry, names.ground_truth))
            self.stall_pubs.append(self._robot_publisher(Bool, names.stall))
            self.scan_pubs.append([self._robot_publisher(LaserScan, topic) for topic in names.scans])
            if stamped:
                self.create_subscription(
                    TwistStamped, names.cmd_vel, lambda msg, i=index: self.on_command(i, msg.twist), RELIABLE_10,
                    event_callbacks=NO_SUB_EVENTS)
            else:
                self.create_subscription(
                    Twist, names.cmd_vel, lambda msg, i=index: self.on_command(i, msg), RELIABLE_10,
                    event_callbacks=NO_SUB_EVENTS)
        self.create_service(Empty, "reset_positions", self.on_reset, qos_profile=EVERY_REQUEST)
        # Messages are built once and refilled every step: publishing serialises them, so reuse is safe.
        self._out = [
            _RobotMessages(
                odom=conversions.odometry_msg(names.odom_frame, names.base_footprint),
                truth=conversions.odometry_msg(fields.WORLD_FRAME, names.base_footprint),
                stall=Bool(),
                odom_tf=conversions.transform(names.odom_frame, names.base_footprint, 0, 0, 0, 0, conversions.stamp(0)),
                scans=[conversions.scan_msg(r, f) for r, f in zip(robot.rangers, names.laser_frames, strict=True)],
            )
            for robot, names in zip(self.sim.robots, self.names, strict=True)
        ]
        self._tf = TFMessage(transforms=[out.odom_tf for out in self._out])

    def destroy_node(self) -> None:
        """Destroy the subscriptions before the publishers: Fast DDS takes time in proportion to the
        participant's readers to delete each writer (1000 robots: 18 s of CPU the other way round)."""
        for subscription in list(self.subscriptions):
            self.destroy_subscription(subscription)
        super().destroy_node()

    def _step_timer(self, start: bool) -> Timer:
        """The steady wall timer that wakes the node every step period (0: at every executor round)."""
        return self.create_timer(
            self.pacer.period, self._step_due, clock=Clock(clock_type=ClockType.STEADY_TIME), autostart=start)

    def _step_due(self) -> None:
        """The steps the pacer says are due now; a node woken late comes back after the callbacks waiting."""
        for _ in self.pacer.steps():
            self.step_once()
        if self.pacer.behind():
            self._catch_up.trigger()

    def _robot_publisher(self, msg_type: type, topic: str) -> Publisher:
        return self.create_publisher(msg_type, topic, RELIABLE_10, event_callbacks=NO_PUB_EVENTS)

    def _publish_static(self) -> None:
        """One latched /tf_static message with every robot's fixed frames (and /map if asked)."""
        time = conversions.stamp(self.sim.sim_time_us)
        edges = fields.static_edges(self.sim.robots, self.names)
        self.tf_static_pub.publish(TFMessage(transforms=[conversions.edge_transform(e, time) for e in edges]))
        if self.map_pub is not None:
            try:
                grid = self.sim.static.to_occupancy_grid()
            except WorldTooLargeError as error:  # the simulation runs on; only the picture is refused
                self.get_logger().warning(f"not publishing /map: {error}")
                return
            self.map_pub.publish(conversions.occupancy_grid_msg(grid, fields.WORLD_FRAME, time))

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
                f"{self.names[robot].cmd_vel}: rejected command {values} (not finite or above "
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
        sim = self.sim
        time = conversions.stamp(sim.sim_time_us)
        self.clock_pub.publish(conversions.clock_msg(sim.sim_time_us))
        true_velocity = sim.true_velocities
        # A message nobody has subscribed to is neither filled nor serialised (asking DDS costs ~1.5 µs, a
        # publish 15-80 µs): with a hundred robots most topics have no reader, and lockstep runs go 2x faster.
        tf_wanted = self.tf_pub.get_subscription_count() > 0
        for i, out in enumerate(self._out):
            odom = sim.odometry_poses[i]
            if self.odom_pubs[i].get_subscription_count():
                self.odom_pubs[i].publish(conversions.fill_odometry(out.odom, odom, sim.velocities[i], time))
            if self.truth_pubs[i].get_subscription_count():
                self.truth_pubs[i].publish(
                    conversions.fill_odometry(out.truth, sim.true_poses[i], true_velocity[i], time))
            if self.stall_pubs[i].get_subscription_count():
                out.stall.data = bool(sim.stalled[i])
                self.stall_pubs[i].publish(out.stall)
            if tf_wanted:
                conversions.fill_planar_transform(out.odom_tf, odom[0], odom[1], odom[2], time)
            for scan, pub, msg in zip(sim.scans[i], self.scan_pubs[i], out.scans, strict=True):
                if fields.is_fresh(scan, sim) and pub.get_subscription_count():
                    pub.publish(conversions.fill_scan(msg, scan, time))
        if tf_wanted:
            self.tf_pub.publish(self._tf)
