"""What recording a bag costs: ``stage_sim run ... --speedup 0`` with and without ``--bag``, and scans recorded
per wall second for 1 and 100 robots.

Run with the venv's python: ``.venv/bin/python benchmarks/bags.py [--duration 30000] [--robots 1 100]``. Each
case runs the console script in its own process (as users run it) and reads the sim and wall time it prints;
one JSON object per line:

Every run steps on the compiled kernels from its first step (``STAGE_SIM_KERNELS=numba``).

- ``overhead``: rooms.world with one robot driven straight for ``--duration`` sim seconds and by the wanderer
  for ``--wander-duration``, and 100 robots for ``--crowd-duration`` (``--cases`` picks some of the three),
  plain and with ``--bag``, ``--repeat`` times each (interleaved in pairs): the best sim seconds per wall
  second of each; ``cost_pct``, how much
  slower the recording run is than the plain run just before it, the median over the pairs (the target:
  <= 15; the machine's speed drifts over minutes, a pair's two runs share its phase), ``cost_pct_pairs`` the
  lowest and highest pair; ``cpu_cost_pct``, the same from the
  CPU seconds of the processes (the simulator and its bag writer), which the load of other processes disturbs
  less; ``threads_plain`` and ``threads_bag``, the threads ``stage_sim run`` simulates on without and with a
  bag (a recording leaves a core to its writer process); when they differ, each pair has a third run, plain
  on the recording's threads, which parts the cost in two medians: ``core_cost_pct``, what giving the core
  away costs a plain run, and ``writer_cost_pct``, what recording costs on the same threads;
  ``neighbour_cost_pct``, the median over the pairs of what a busy neighbour costs a plain run on the
  recording's threads: the same run while another process spins (a Python loop) on the core left to the writer.
  Any writer process costs the simulation that share of its rate for the fraction of the time it is busy (on
  a machine whose two vCPUs share a physical core, or a power budget, a busy neighbour slows a core down);
  ``setup_s_plain`` and ``setup_s_bag``, the wall seconds of each process outside its run (imports,
  loading the world, and with a bag starting its writer process), which the rates leave out.
- ``throughput``: N robots with a 240-beam laser on the rooms map (benchmarks/simulate.py's worlds), recorded:
  LaserScans in the bag per wall second, the bag's size and how many steps were dropped.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mcap.reader import make_reader

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
sys.path.insert(0, str(REPO))

from simulate import world_text  # noqa: E402 - the benchmark worlds of N robots, shared with simulate.py

from stage_sim.runs.pacing import threads_for_run  # noqa: E402 - the threads stage_sim run chooses

STAGE_SIM = Path(sys.executable).with_name("stage_sim")
RATE = re.compile(r": ([\d.]+) s of sim time in ([\d.]+) s of wall time")


CASES = ("straight", "wander", "crowd")
BUSY = "while True: pass"
"""The busy neighbour: a process that keeps a core busy, as a bag writer that never waits would."""


def run(world: Path, duration: float, controller: str, bag: Path | None, threads: int | None = None,
        neighbour: bool = False) -> dict:
    """One ``stage_sim run`` (on ``threads`` threads, else its own choice; beside a busy process if
    ``neighbour``): sim and wall seconds it reports, and what the bag holds."""
    if neighbour:
        with subprocess.Popen([sys.executable, "-c", BUSY]) as busy:
            try:
                return run(world, duration, controller, bag, threads)
            finally:
                busy.kill()
    command = [str(STAGE_SIM), "run", str(world), "--duration", str(duration), "--speedup", "0",
               "--controller", controller, "--seed", "1"]
    if bag is not None:
        command += ["--bag", str(bag)]
    if threads is not None:
        command += ["--threads", str(threads)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.monotonic()
    # The compiled kernels from the first step: a run of a few wall seconds would otherwise spend most of them
    # on numpy while numba loads in the background, and measure that.
    result = subprocess.run(command, capture_output=True, text=True, check=True,
                            env={**os.environ, "STAGE_SIM_KERNELS": "numba"})
    process_s = time.monotonic() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    sim_s, wall_s = map(float, RATE.search(result.stdout).groups())
    cpu_s = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    out = {"sim_s": sim_s, "wall_s": wall_s, "sim_rate": round(sim_s / wall_s, 2), "cpu_s": cpu_s,
           "setup_s": process_s - wall_s}
    if bag is not None:
        with bag.open("rb") as stream:
            reader = make_reader(stream)
            summary = reader.get_summary()
            dropped = next(m.metadata for m in reader.iter_metadata() if m.name == "stage_sim")
        counts = summary.statistics.channel_message_counts
        out["scans"] = sum(counts.get(i, 0) for i, c in summary.channels.items()
                           if summary.schemas[c.schema_id].name == "sensor_msgs/msg/LaserScan")
        out["bag_mb"] = round(bag.stat().st_size / 2**20, 2)
        out["dropped_steps"] = int(dropped["dropped_steps"])
    return out


def overhead(world: Path, robots: int, controller: str, duration: float, repeat: int, bag: Path) -> dict:
    """Plain and recorded runs of one case, interleaved in pairs: the cost is the median of the pairs' costs
    (the runs of a pair share the machine's phase; its speed drifts by tens of percent over minutes), the
    rates the best of each. When a recording simulates on fewer threads than a plain run (it leaves a core
    to its writer), each pair also has a plain run on those threads: what the core given away costs, and
    what the writer costs on top of it. Each pair also has a plain run on those threads beside a busy process:
    what any busy writer would cost."""
    full, fewer = threads_for_run(None, 0.0), threads_for_run(None, 0.0, recording=True)
    plains, bags, narrow, beside = [], [], [], []
    for _ in range(repeat):
        plains.append(run(world, duration, controller, None))
        narrow.append(run(world, duration, controller, None, fewer) if fewer < full else plains[-1])
        beside.append(run(world, duration, controller, None, fewer, neighbour=True))
        bags.append(run(world, duration, controller, bag))
    plain, recorded = max(plains, key=lambda r: r["sim_rate"]), max(bags, key=lambda r: r["sim_rate"])
    cpu_plain, cpu_bag = min(r["cpu_s"] for r in plains), min(r["cpu_s"] for r in bags)
    costs = _pair_costs(plains, bags)
    return {
        "case": "overhead", "world": world.name, "robots": robots, "controller": controller, "duration": duration,
        "repeat": repeat, "sim_rate_plain": plain["sim_rate"], "sim_rate_bag": recorded["sim_rate"],
        "cost_pct": round(statistics.median(costs), 1),
        "cost_pct_pairs": f"{min(costs):.1f} to {max(costs):.1f}",
        "cpu_s_plain": round(cpu_plain, 2), "cpu_s_bag": round(cpu_bag, 2),
        "cpu_cost_pct": round(100 * (cpu_bag / cpu_plain - 1), 1),
        "setup_s_plain": round(min(r["setup_s"] for r in plains), 2),
        "setup_s_bag": round(min(r["setup_s"] for r in bags), 2),
        "bag_mb": recorded["bag_mb"], "dropped_steps": recorded["dropped_steps"],
        "threads_plain": full, "threads_bag": fewer,
        "neighbour_cost_pct": round(statistics.median(_pair_costs(narrow, beside)), 1),
        # The two parts of the cost when the recording gives a core away, medians of the same pairs.
        **({"core_cost_pct": round(statistics.median(_pair_costs(plains, narrow)), 1),
            "writer_cost_pct": round(statistics.median(_pair_costs(narrow, bags)), 1)} if fewer < full else {})}


def _pair_costs(before: list[dict], after: list[dict]) -> list[float]:
    """How much slower each run of ``after`` is than its pair in ``before`` (%)."""
    return [100 * (1 - b["sim_rate"] / a["sim_rate"]) for a, b in zip(before, after, strict=True)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=30000.0,
                        help="sim seconds of the one-robot overhead runs driven straight (a few wall seconds: runs "
                             "of under a second gave pairs 50 points apart)")
    parser.add_argument("--wander-duration", type=float, default=600.0,
                        help="sim seconds of the one-robot overhead runs driven by the wanderer")
    parser.add_argument("--crowd-duration", type=float, default=60.0,
                        help="sim seconds of the 100-robot overhead runs")
    parser.add_argument("--repeat", type=int, default=5, help="overhead pairs of runs (plain, recorded) per case")
    parser.add_argument("--cases", nargs="+", choices=CASES, default=list(CASES),
                        help="overhead cases: one robot driven straight, by the wanderer, 100 robots")
    parser.add_argument("--robots", type=int, nargs="+", default=[1, 100])
    parser.add_argument("--throughput-duration", type=float, default=None,
                        help="sim seconds of each throughput run (default: 600 for one robot, 30 for more)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        rooms = REPO / "worlds" / "rooms.world"
        crowd = tmp / "robots_100.world"
        crowd.write_text(world_text(100, 240, 240.0, 5.6, seed=1))
        cases = {"straight": (rooms, 1, "straight", args.duration),
                 "wander": (rooms, 1, "wander", args.wander_duration),
                 "crowd": (crowd, 100, "straight", args.crowd_duration)}
        for world, robots, controller, duration in (cases[name] for name in args.cases):
            print(json.dumps(overhead(world, robots, controller, duration, args.repeat, tmp / "overhead.mcap")),
                  flush=True)
        for robots in args.robots:
            world = tmp / f"robots_{robots}.world"
            world.write_text(world_text(robots, 240, 240.0, 5.6, seed=1))
            duration = args.throughput_duration or (600.0 if robots == 1 else 30.0)
            result = run(world, duration, "straight", tmp / f"robots_{robots}.mcap")
            print(json.dumps({
                "case": "throughput", "robots": robots, "beams": 240, "duration": duration,
                "scans": result["scans"], "wall_s": result["wall_s"],
                "scans_per_wall_s": round(result["scans"] / result["wall_s"], 1), "sim_rate": result["sim_rate"],
                "bag_mb": result["bag_mb"], "dropped_steps": result["dropped_steps"]}), flush=True)


if __name__ == "__main__":
    main()
