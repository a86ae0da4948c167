"""Start-up: wall seconds from starting ``stageros rooms.world`` to its first /base_scan, cold and warm cache.

Run with the venv's python: ``.venv/bin/python benchmarks/startup.py [--runs N]``. Prints one JSON object
per line: ``case`` ("cold cache": the default kernels with an empty numba cache folder, so numba compiles
every kernel, in the background while the first steps run on numpy (sim/kernel_upgrade.py); "warm cache":
the same folder, now filled; "numba from the start": ``STAGE_SIM_KERNELS=numba``, the first scan waits for
numba; "numpy kernels": no numba at all), ``run``, ``simulation_built_s`` (stageros logs that its world
is loaded and simulated; it publishes its first scan one step, 0.1 s, later) and ``first_scan_s`` (this
process receives it). The subscriber is up before stageros starts; the gap between the two figures is
DDS discovery (Fast DDS takes ~3.5 s here before the subscriber even sees the publisher, whatever the kernels).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from sensor_msgs.msg import LaserScan

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from stage_sim.ros.domain import use_private_domain  # noqa: E402

STAGEROS = Path(sys.executable).with_name("stageros")


def first_scan(env: dict[str, str], timeout: float = 120.0) -> tuple[float, float | None]:
    """Seconds from launching stageros until it logs that its simulation is built (it publishes the first
    scan one step later), and until this process receives its first /base_scan."""
    rclpy.init()
    node = rclpy.create_node("startup_benchmark")
    got: list[float] = []
    node.create_subscription(LaserScan, "/base_scan", lambda _: got.append(time.monotonic()), QoSProfile(depth=10))
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    start = time.monotonic()
    process = subprocess.Popen([str(STAGEROS), str(REPO / "worlds" / "rooms.world")], env=env,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    ready: list[float] = []

    def watch_log() -> None:  # stageros logs "<world>: N robot(s), interval_sim ..." once its simulation is built
        for line in process.stderr:
            if "interval_sim" in line and not ready:
                ready.append(time.monotonic())

    threading.Thread(target=watch_log, daemon=True).start()
    try:
        while not got and time.monotonic() - start < timeout:
            executor.spin_once(timeout_sec=0.01)
    finally:
        process.terminate()
        process.wait(timeout=timeout)  # a stageros stopped while numba compiles exits once the compiler is done
        node.destroy_node()
        rclpy.shutdown()
    if not got:
        raise SystemExit(f"no /base_scan within {timeout} s")
    return (ready[0] - start if ready else None), got[0] - start


def main() -> None:
    use_private_domain(Path(__file__).name)  # a simulator running beside this benchmark must not be measured
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="warm-cache runs (the cold run is one)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as cache:
        env = {key: value for key, value in os.environ.items() if key != "STAGE_SIM_KERNELS"}
        env["NUMBA_CACHE_DIR"] = cache
        cases = [("cold cache", env)] + [("warm cache", env)] * args.runs
        cases += [("numba from the start", dict(env, STAGE_SIM_KERNELS="numba"))] * args.runs
        cases += [("numpy kernels", dict(env, STAGE_SIM_KERNELS="numpy"))] * args.runs
        for run, (case, case_env) in enumerate(cases):
            built, received = first_scan(case_env)
            print(json.dumps({"case": case, "run": run, "simulation_built_s": built and round(built, 2),
                              "first_scan_s": round(received, 2)}), flush=True)


if __name__ == "__main__":
    main()
