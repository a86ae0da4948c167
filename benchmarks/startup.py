"""Start-up: wall seconds from starting ``stageros rooms.world`` to its first /base_scan, cold and warm cache,
and from starting ``stageros`` on a world of 1000 robots to its first /robot_0/base_scan.

Run with the venv's python: ``.venv/bin/python benchmarks/startup.py [--runs N] [--cases CASE ...]``. Prints
one JSON object per line: ``case`` ("cold cache": the default kernels with an empty numba cache folder, so numba
compiles every kernel, in the background while the first steps run on numpy (sim/kernel_upgrade.py); "warm cache":
the same folder, now filled; "numba from the start": ``STAGE_SIM_KERNELS=numba``, the first scan waits for
numba; "numpy kernels": no numba at all; "1000 robots": Stage's hospital.world benchmark, warm cache),
``world``, ``run``, ``simulation_built_s`` (stageros logs that its world is loaded and simulated and its
topics advertised; it publishes its first scan one step, 0.1 s, later), ``built_cpu_s`` (the CPU seconds
stageros had used by then) and ``first_scan_s`` (this process receives it). The subscriber is up before
stageros starts; the gap between the two figures is DDS discovery (Fast DDS takes ~3.5 s here before the
subscriber even sees the publisher, whatever the kernels). With 1000 robots most of the set-up is the
middleware's: Fast DDS matches every new publisher against every subscription of the process and the other way
round, about 1.5 us of CPU a pair, 4000 publishers by 1000 subscriptions.
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
from dataclasses import dataclass
from pathlib import Path

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from sensor_msgs.msg import LaserScan

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
sys.path.insert(0, str(REPO))

from stageros import cpu_seconds  # noqa: E402 - a process's CPU seconds from /proc, shared with stageros.py

from stage_sim.ros.domain import use_private_domain  # noqa: E402

STAGEROS = Path(sys.executable).with_name("stageros")
ROOMS = REPO / "worlds" / "rooms.world"
CROWD = REPO / "tests" / "data" / "corpus" / "stage-worlds" / "benchmark" / "hospital.world"
"""Stage's own 1000-robot benchmark world, which travels with the tests' corpus."""
CASES = ["cold cache", "warm cache", "numba from the start", "numpy kernels", "1000 robots"]


@dataclass(frozen=True)
class Startup:
    """One start of stageros: wall seconds until its simulation was built (None if it never said) and until
    the first scan arrived here, and the CPU seconds stageros had used when it was built."""

    built_s: float | None
    built_cpu_s: float | None
    first_scan_s: float


def first_scan(env: dict[str, str], world: Path, topic: str, timeout: float = 120.0) -> Startup:
    """Launch stageros on ``world`` and time it until it logs that its simulation is built (it publishes the
    first scan one step later) and until this process receives its first message on ``topic``."""
    rclpy.init()
    node = rclpy.create_node("startup_benchmark")
    got: list[float] = []
    node.create_subscription(LaserScan, topic, lambda _: got.append(time.monotonic()), QoSProfile(depth=10))
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    start = time.monotonic()
    process = subprocess.Popen([str(STAGEROS), str(world)], env=env,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    ready: list[tuple[float, float]] = []

    def watch_log() -> None:  # stageros logs "<world>: N robot(s), interval_sim ..." once its simulation is built
        for line in process.stderr:
            if "interval_sim" in line and not ready:
                ready.append((time.monotonic(), cpu_seconds(process.pid)))

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
        raise SystemExit(f"no {topic} within {timeout} s")
    built, cpu = ready[0] if ready else (None, None)
    return Startup(built and built - start, cpu, got[0] - start)


def main() -> None:
    use_private_domain(Path(__file__).name)  # a simulator running beside this benchmark must not be measured
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="warm-cache runs (the cold run is one)")
    parser.add_argument("--cases", nargs="+", choices=CASES, default=CASES, metavar="CASE",
                        help=f"the cases to run, in this order: {', '.join(CASES)} (default: all; a warm "
                             "cache is warm only after the cold one: the cache folder is new each time)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as cache:
        env = {key: value for key, value in os.environ.items() if key != "STAGE_SIM_KERNELS"}
        env["NUMBA_CACHE_DIR"] = cache
        rooms = (ROOMS, "/base_scan")
        cases = [("cold cache", env, rooms)] + [("warm cache", env, rooms)] * args.runs
        cases += [("numba from the start", dict(env, STAGE_SIM_KERNELS="numba"), rooms)] * args.runs
        cases += [("numpy kernels", dict(env, STAGE_SIM_KERNELS="numpy"), rooms)] * args.runs
        cases += [("1000 robots", env, (CROWD, "/robot_0/base_scan"))] * args.runs
        cases = [case for case in cases if case[0] in args.cases]
        for run, (case, case_env, (world, topic)) in enumerate(cases):
            startup = first_scan(case_env, world, topic)
            print(json.dumps({"case": case, "world": world.name, "run": run,
                              "simulation_built_s": startup.built_s and round(startup.built_s, 2),
                              "built_cpu_s": startup.built_cpu_s,
                              "first_scan_s": round(startup.first_scan_s, 2)}), flush=True)


if __name__ == "__main__":
    main()
