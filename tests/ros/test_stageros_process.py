"""stageros as users run it: the console script in its own process, driven from this one."""

from __future__ import annotations

import itertools
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty

from stage_sim.runs.pacing import MAX_LAG_S
from tests.ros.helpers import spin_until

STAGEROS = Path(sys.executable).with_name("stageros")


def start_stageros(cwd: Path, *args: str) -> subprocess.Popen:
    """The console script on the bundled rooms world, from a directory that does not hold it."""
    return subprocess.Popen(
        [str(STAGEROS), "-g", *args, "rooms.world"], cwd=cwd, env=dict(os.environ),
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )


def stop(process: subprocess.Popen) -> tuple[int, str]:
    process.send_signal(signal.SIGINT)
    try:
        output, _ = process.communicate(timeout=15)
    except subprocess.TimeoutExpired:
        process.kill()
        output, _ = process.communicate()
        raise
    return process.returncode, output


def rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise AssertionError("no VmRSS")


def seconds(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


@pytest.mark.slow
def test_console_script_scans_drives_resets_and_exits_on_ctrl_c(ros_context, executor, tmp_path) -> None:
    # No watchdog: on a busy machine this process's commands can come further apart than its 0.2 sim s (50 ms
    # at 4x), and a robot it stopped would look as if the stop below had been taken while drive commands were
    # still on their way (they then moved it after the reset).
    process = start_stageros(tmp_path, "--speedup", "4", "--ros-args", "-p", "base_watchdog_timeout:=0.0", "--")
    try:
        node = Node("driver", context=ros_context)
        executor.add_node(node)
        scans: list[LaserScan] = []
        truth: list[Odometry] = []
        node.create_subscription(LaserScan, "base_scan", scans.append, 100)
        node.create_subscription(Odometry, "base_pose_ground_truth", truth.append, 100)
        assert spin_until(executor, lambda: len(scans) >= 5 and truth, timeout_s=30), process.poll()
        stamps = [seconds(s.header.stamp) for s in scans[-5:]]
        assert [round(b - a, 6) for a, b in itertools.pairwise(stamps)] == [0.1] * 4
        assert len(scans[-1].ranges) == 240 and scans[-1].header.frame_id == "base_laser_link"
        start = truth[-1].pose.pose.position
        start_xy = (start.x, start.y)

        cmd = node.create_publisher(Twist, "cmd_vel", 10)
        forward = Twist()
        forward.angular.z = 0.8
        forward.linear.x = 0.2
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            cmd.publish(forward)
            executor.spin_once(timeout_sec=0.02)
            p = truth[-1].pose.pose.position
            if math.hypot(p.x - start_xy[0], p.y - start_xy[1]) > 0.1:
                break
        moved = truth[-1].pose.pose.position
        assert math.hypot(moved.x - start_xy[0], moved.y - start_xy[1]) > 0.1
        # Stop, and wait until it stands: drive commands still queued in a busy node would otherwise be
        # applied after the reset.
        cmd.publish(Twist())

        def standing() -> bool:
            a, b = truth[-2].pose.pose.position, truth[-1].pose.pose.position
            return (a.x, a.y) == (b.x, b.y)

        assert spin_until(executor, standing, timeout_s=10)

        client = node.create_client(Empty, "reset_positions")
        assert client.wait_for_service(timeout_sec=10)
        future = client.call_async(Empty.Request())
        executor.spin_until_future_complete(future, timeout_sec=10)
        assert future.done()
        count = len(truth)
        assert spin_until(executor, lambda: len(truth) >= count + 3, timeout_s=10)
        back = truth[-1].pose.pose.position
        assert (back.x, back.y) == pytest.approx(start_xy, abs=1e-6)
    finally:
        code, output = stop(process)
    assert code == 0, output


SLOW_SUBSCRIBER = """
import time, rclpy
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage
rclpy.init()
node = rclpy.create_node("slow_subscriber")
node.create_subscription(LaserScan, "base_scan", lambda m: time.sleep(1.0), 10)
node.create_subscription(TFMessage, "/tf", lambda m: time.sleep(1.0), 10)
rclpy.spin(node)
"""


@pytest.mark.slow
def test_floods_reset_storms_and_slow_subscribers_neither_slow_the_clock_nor_grow_memory(
    ros_context, executor, tmp_path
) -> None:
    log = tmp_path / "stageros.log"
    with log.open("w") as sink:  # a file, so that the log can be read while stageros runs
        default_kernels = {k: v for k, v in os.environ.items() if k != "STAGE_SIM_KERNELS"}
        process = subprocess.Popen([str(STAGEROS), "-g", "rooms.world"], cwd=tmp_path, env=default_kernels,
                                   stdout=sink, stderr=subprocess.STDOUT)
    slow = subprocess.Popen([sys.executable, "-c", SLOW_SUBSCRIBER], env=dict(os.environ))
    try:
        node = Node("flooder", context=ros_context)
        executor.add_node(node)
        clock: list[tuple[float, float]] = []
        node.create_subscription(Clock, "/clock", lambda m: clock.append((time.monotonic(), seconds(m.clock))), 100)
        cmd = node.create_publisher(Twist, "cmd_vel", 10)
        reset = node.create_client(Empty, "reset_positions")
        assert spin_until(executor, lambda: len(clock) >= 5 and cmd.get_subscription_count() > 0, timeout_s=30)
        assert reset.wait_for_service(timeout_sec=10)
        # The baseline is taken once the compiled kernels have replaced the numpy ones they start on (numba
        # loads on its own thread for a second or two and adds ~60 MB): growth after that would be a leak.
        assert spin_until(executor, lambda: "simulation kernels: numba" in log.read_text(), timeout_s=60)
        # The swap pauses the steps for a moment, which the node then catches up (up to MAX_LAG_S): the clock's
        # rate is measured from once that is done.
        settled = time.monotonic() + MAX_LAG_S + 0.5
        spin_until(executor, lambda: time.monotonic() > settled, timeout_s=2 * MAX_LAG_S)
        rss_before = rss_mb(process.pid)
        values = [math.nan, 1e9, -math.inf, 0.3, 0.0, 5e3, 0.5]
        messages = [Twist() for _ in values]
        for msg, value in zip(messages, values, strict=True):
            msg.linear.x = value
            msg.angular.z = -value if math.isfinite(value) else value
        window_start = len(clock)
        sent, resets, start = 0, [], time.monotonic()
        while (now := time.monotonic()) - start < 10.0:
            while sent < (now - start) * 2000:
                cmd.publish(messages[sent % len(messages)])
                sent += 1
            if len(resets) < (now - start) * 50:  # a reset storm: 50 calls per second
                resets.append(reset.call_async(Empty.Request()))
            executor.spin_once(timeout_sec=0)
        assert sent >= 19_000
        assert spin_until(executor, lambda: all(f.done() for f in resets), timeout_s=10)
        window = clock[window_start:]
        (wall0, sim0), (wall1, sim1) = window[0], window[-1]
        rate = (sim1 - sim0) / (wall1 - wall0)
        assert rate == pytest.approx(1.0, abs=0.05)
        growth = rss_mb(process.pid) - rss_before
        assert growth < 20, f"resident memory grew by {growth:.1f} MB"
    finally:
        slow.kill()
        slow.wait()
        process.send_signal(signal.SIGINT)
        code = process.wait(timeout=15)
    output = log.read_text()
    assert code == 0, output
    assert "rejected command" in output


def test_a_broken_world_exits_2_with_its_location_and_no_traceback(tmp_path) -> None:
    broken = tmp_path / "broken.world"
    broken.write_text('resolution 0.02\nposition( pose [1 2 0 0] drive "hover" )\n')
    result = subprocess.run([str(STAGEROS), "-g", str(broken)], capture_output=True, text=True, timeout=60,
                            env=dict(os.environ))
    assert result.returncode == 2
    assert f"{broken}:2:" in result.stderr
    assert "hover" in result.stderr
    assert "Traceback" not in result.stderr + result.stdout


def test_a_missing_world_names_the_bundled_ones(tmp_path) -> None:
    result = subprocess.run([str(STAGEROS), "-g", "no_such.world"], capture_output=True, text=True, timeout=60,
                            cwd=tmp_path, env=dict(os.environ))
    assert result.returncode == 2
    assert "rooms.world" in result.stderr and "Traceback" not in result.stderr


def test_quit_time_ends_the_node_cleanly(tmp_path) -> None:
    world = tmp_path / "short.world"
    world.write_text('quit_time 3\nresolution 0.02\nmodel( size [1 1 1] pose [3 0 0 0] )\nposition( pose [0 0 0 0] )\n')
    result = subprocess.run([str(STAGEROS), "-g", "--speedup", "0", str(world)], capture_output=True, text=True,
                            timeout=60, env=dict(os.environ))
    assert result.returncode == 0, result.stderr
    assert "quit_time 3 s reached" in result.stderr + result.stdout


def test_record_writes_a_gif_of_the_run(tmp_path) -> None:
    from PIL import Image

    world = tmp_path / "short.world"
    world.write_text('quit_time 2\nresolution 0.02\nmodel( size [1 1 1] pose [3 0 0 0] )\nposition( pose [0 0 0 0] )\n')
    gif = tmp_path / "run.gif"
    result = subprocess.run([str(STAGEROS), "-g", "--speedup", "0", "--record", str(gif), "--record-every", "0.5",
                             str(world)], capture_output=True, text=True, timeout=60, env=dict(os.environ))
    assert result.returncode == 0, result.stderr
    with Image.open(gif) as image:
        assert image.n_frames == 2 / 0.5 + 1  # the start and one frame every 0.5 s up to quit_time
