"""The stageros process as users run it: CPU share at real time and real-time factor with --speedup 0.

Run with the venv's python: ``.venv/bin/python benchmarks/stageros.py``. Prints one JSON object per line:
``case``, ``world``, ``robots``, ``wall_s``, ``sim_s``, ``realtime_factor``, ``cpu_share`` (process CPU
seconds per wall second, 1.0 = one full core). Sim time is read from the node's /clock by a subscriber in
this process; CPU time from /proc of the stageros process.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rosgraph_msgs.msg import Clock

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
sys.path.insert(0, str(REPO))

from stage_sim.ros.domain import use_private_domain  # noqa: E402

STAGEROS = Path(sys.executable).with_name("stageros")
TICKS = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid: int) -> float:
    """CPU seconds a running process has used so far (all its threads), from /proc."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def measure(case: str, world: Path, robots: int, speedup: str, wall_s: float) -> dict:
    process = subprocess.Popen([str(STAGEROS), "-g", "--speedup", speedup, str(world)], env=dict(os.environ),
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    rclpy.init()
    node = rclpy.create_node("stageros_benchmark")
    clock: list[float] = []
    node.create_subscription(Clock, "/clock", lambda m: clock.append(m.clock.sec + m.clock.nanosec * 1e-9), 1000)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        deadline = time.monotonic() + 60
        while len(clock) < 3 and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.05)
        sim0, cpu0, wall0 = clock[-1], cpu_seconds(process.pid), time.monotonic()
        while time.monotonic() - wall0 < wall_s:
            executor.spin_once(timeout_sec=0.05)
        sim1, cpu1, wall1 = clock[-1], cpu_seconds(process.pid), time.monotonic()
    finally:
        process.terminate()
        process.wait(timeout=20)
        node.destroy_node()
        rclpy.shutdown()
    return {"case": case, "world": world.name, "robots": robots, "wall_s": round(wall1 - wall0, 2),
            "sim_s": round(sim1 - sim0, 2), "realtime_factor": round((sim1 - sim0) / (wall1 - wall0), 2),
            "cpu_share": round((cpu1 - cpu0) / (wall1 - wall0), 3)}


def main() -> None:
    use_private_domain(Path(__file__).name)  # a simulator running beside this benchmark must not be measured
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="wall seconds measured per case")
    args = parser.parse_args()
    rooms = REPO / "worlds" / "rooms.world"
    print(json.dumps(measure("real time", rooms, 1, "1", args.seconds)), flush=True)
    print(json.dumps(measure("as fast as possible", rooms, 1, "0", args.seconds)), flush=True)
    from simulate import world_text

    with tempfile.TemporaryDirectory() as tmp:
        hundred = Path(tmp) / "hundred.world"
        hundred.write_text(world_text(100, 240, 240.0, 5.6, 1))
        print(json.dumps(measure("as fast as possible", hundred, 100, "0", args.seconds)), flush=True)


if __name__ == "__main__":
    main()
