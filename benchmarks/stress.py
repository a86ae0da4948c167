"""Same seed, same run, whatever the load; nothing recorded is lost: stage_sim's guarantees under stress.

Run with the venv's python: ``.venv/bin/python benchmarks/stress.py [--quick] [--checks frozen ...]``.
Each check prints one JSON object per line (``"ok"`` says whether the guarantee held):

* ``frozen``: ``launch_scripts/reactive.py --speedup 0 --seed S`` (lockstep) recorded into a bag, once on its
  own and once frozen with SIGSTOP and resumed at random moments (as a starved process is): the JSON
  summaries and the bags (message for message: topic, log time, bytes) must be identical;
* ``concurrent``: two such runs at once while busy processes keep every core loaded: both identical to the
  quiet run;
* ``complete``: ``stage_sim run`` with N robots in lockstep recorded into a bag: every step of every robot is
  in it (steps recorded / steps simulated);
* ``kill9``: ``stage_sim run rooms.world --speedup 1 --bag`` killed with SIGKILL after 5, 20 and 60 s of
  real time, then ``stage_sim recover``: the sim seconds lost (about one: a chunk spans a sim second);
* ``soak``: ``stageros`` at real time with a bag and the browser view open (a client reading its frames),
  under a ``cmd_vel`` flood and a storm of ``reset_positions`` calls: its sim rate per window and its
  memory (after a first window of warm-up), which must stay within 5 % of real time and flat.

``--quick`` runs tiny sizes (seconds, not minutes): what ``make test`` runs (tests/benchmarks) so that the
checks themselves cannot rot; the figures that count come from the full sizes.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import multiprocessing
import os
import random
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
sys.path.insert(0, str(REPO))

from mcap.reader import make_reader  # noqa: E402
from simulate import world_text  # noqa: E402 - the benchmark worlds of N robots

REACTIVE = REPO / "launch_scripts" / "reactive.py"
BIN = Path(sys.executable).parent


@dataclass(frozen=True)
class Sizes:
    """How long and how large each check runs."""

    lockstep_s: float  # sim seconds of the reactive runs
    robots: int  # robots of the completeness run
    complete_s: float  # its sim seconds
    soak_s: float  # wall seconds of the soak
    window_s: float  # wall seconds per rate sample of the soak
    kill_after_s: tuple[float, ...]  # wall seconds of real-time recording before each kill -9


FULL = Sizes(lockstep_s=300.0, robots=100, complete_s=600.0, soak_s=600.0, window_s=30.0, kill_after_s=(5, 20, 60))
QUICK = Sizes(lockstep_s=10.0, robots=10, complete_s=20.0, soak_s=12.0, window_s=3.0, kill_after_s=(2,))


def bag_messages(path: Path) -> list[tuple[str, int, bytes]]:
    """Every message of a bag in file order: (topic, log time, serialised bytes)."""
    with path.open("rb") as stream:
        reader = make_reader(stream)
        return [(channel.topic, message.log_time, message.data)
                for _, channel, message in reader.iter_messages(log_time_order=False)]


def reactive_run(seed: int, duration: float, bag: Path, freeze: bool = False) -> tuple[list[str], Path]:
    """One lockstep reactive.py run (optionally frozen and resumed at random moments): its summary lines."""
    env = dict(os.environ)
    env.pop("ROS_DOMAIN_ID", None)  # each run takes a private domain of its own
    process = subprocess.Popen(
        [sys.executable, str(REACTIVE), "-g", "--speedup", "0", "--seed", str(seed), "--duration", str(duration),
         "--bag", str(bag)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    freezer = threading.Thread(target=_freeze_at_random, args=(process, seed), daemon=True) if freeze else None
    if freezer:
        freezer.start()
    out, err = process.communicate()
    if process.returncode != 0:
        raise RuntimeError(f"reactive.py exited {process.returncode}: {err[-2000:]}")
    return [line for line in out.splitlines() if line.startswith("{")], bag


def _freeze_at_random(process: subprocess.Popen, seed: int) -> None:
    """SIGSTOP the process for 0.05-0.7 s at random moments until it ends (a starved process)."""
    rng = random.Random(seed)
    while process.poll() is None:
        time.sleep(rng.uniform(0.05, 0.5))
        try:
            process.send_signal(signal.SIGSTOP)
            time.sleep(rng.uniform(0.05, 0.7))
            process.send_signal(signal.SIGCONT)
        except ProcessLookupError:
            return


def _spin(stop: Any) -> None:
    """Keep one core busy until ``stop`` (a multiprocessing Event) is set."""
    while not stop.is_set():
        sum(range(10_000))


def check_frozen(sizes: Sizes, folder: Path) -> dict:
    quiet, quiet_bag = reactive_run(1234, sizes.lockstep_s, folder / "quiet.mcap")
    frozen, frozen_bag = reactive_run(1234, sizes.lockstep_s, folder / "frozen.mcap", freeze=True)
    same_bag = bag_messages(quiet_bag) == bag_messages(frozen_bag)
    return {"check": "frozen", "sim_s": sizes.lockstep_s, "same_summaries": quiet == frozen, "same_bag": same_bag,
            "messages": len(bag_messages(quiet_bag)), "ok": quiet == frozen and same_bag}


def check_concurrent(sizes: Sizes, folder: Path) -> dict:
    quiet, quiet_bag = reactive_run(4242, sizes.lockstep_s, folder / "alone.mcap")
    expected = bag_messages(quiet_bag)
    stop = multiprocessing.Event()
    spinners = [multiprocessing.Process(target=_spin, args=(stop,)) for _ in range(os.cpu_count() or 2)]
    for spinner in spinners:
        spinner.start()
    try:
        results: list[tuple[list[str], Path]] = [None, None]  # type: ignore[list-item]
        threads = [threading.Thread(target=lambda i=i: results.__setitem__(
            i, reactive_run(4242, sizes.lockstep_s, folder / f"busy_{i}.mcap"))) for i in range(2)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        stop.set()
        for spinner in spinners:
            spinner.join()
    same = [summary == quiet and bag_messages(bag) == expected for summary, bag in results]
    return {"check": "concurrent", "sim_s": sizes.lockstep_s, "busy_processes": len(spinners),
            "identical_runs": sum(same), "of": 2, "ok": all(same)}


def check_complete(sizes: Sizes, folder: Path) -> dict:
    world = folder / f"robots_{sizes.robots}.world"
    world.write_text(world_text(sizes.robots, 240, 240.0, 5.6, seed=1))
    bag = folder / "complete.mcap"
    started = time.monotonic()
    result = subprocess.run([str(BIN / "stage_sim"), "run", str(world), "--duration", str(sizes.complete_s),
                             "--speedup", "0", "--bag", str(bag)], capture_output=True, text=True)
    wall = time.monotonic() - started
    steps = round(sizes.complete_s / 0.1)
    with bag.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    counts = {summary.channels[i].topic: n for i, n in summary.statistics.channel_message_counts.items()}
    scans = [n for topic, n in counts.items() if topic.endswith("base_scan")]
    recorded = min([counts.get("/clock", 0), *scans])
    return {"check": "complete", "robots": sizes.robots, "sim_s": sizes.complete_s, "wall_s": round(wall, 1),
            "steps_simulated": steps, "steps_recorded": recorded, "exit_status": result.returncode,
            "ok": result.returncode == 0 and recorded == steps and len(scans) == sizes.robots}


def check_kill9(sizes: Sizes, folder: Path) -> dict:
    """Sim seconds a kill -9 loses of a real-time recording: wall time since the bag appeared (the run starts
    stepping right after creating it, so this slightly overcounts) minus the last /clock recovered. Killed are
    the simulator alone (its bag writer, a process of its own, then completes the bag) and the simulator with
    its writer (the process group: as a power cut does; ``stage_sim recover`` then reads up to the last chunk)."""
    from stage_sim.bags.recover import recover

    lost: dict[str, dict[str, float]] = {"simulator": {}, "group": {}}
    for after in sizes.kill_after_s:
        for victim in lost:
            bag = folder / f"killed_{victim}_{after:g}.mcap"
            process = subprocess.Popen([str(BIN / "stage_sim"), "run", "rooms.world", "--speedup", "1", "--bag",
                                        str(bag)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                       start_new_session=True)
            while not bag.exists():
                time.sleep(0.005)
            started = time.monotonic()
            time.sleep(after)
            writers = _children(process.pid)
            if victim == "group":
                os.killpg(process.pid, signal.SIGKILL)
            else:
                process.kill()
            ran = time.monotonic() - started
            process.wait()
            for pid in writers:
                _wait_until_gone(pid)
            recovered = folder / f"recovered_{victim}_{after:g}.mcap"
            recover(bag, recovered)
            clocks = [t for topic, t, _ in bag_messages(recovered) if topic == "/clock"]
            lost[victim][f"{after:g}"] = round(ran - (clocks[-1] / 1e9 if clocks else 0.0), 2)
    return {"check": "kill9", "lost_sim_s_after_wall_s": lost,
            "ok": all(v <= 1.5 for by_time in lost.values() for v in by_time.values())}


def _children(pid: int) -> list[int]:
    """The process ids of ``pid``'s children (a recording's bag writer)."""
    return [int(child) for task in os.listdir(f"/proc/{pid}/task")
            for child in Path(f"/proc/{pid}/task/{task}/children").read_text().split()]


def _wait_until_gone(pid: int, timeout_s: float = 60.0) -> None:
    """Until process ``pid`` has ended (gone, or a zombie nobody reaps)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            if Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z":
                return
        except FileNotFoundError:
            return
        time.sleep(0.02)
    raise RuntimeError(f"process {pid} did not end")


def check_soak(sizes: Sizes, folder: Path) -> dict:
    """stageros at real time, recorded, viewed, flooded and reset; its rate and memory over time."""
    import rclpy
    from geometry_msgs.msg import Twist
    from rclpy.executors import SingleThreadedExecutor
    from rosgraph_msgs.msg import Clock
    from std_srvs.srv import Empty

    from stage_sim.ros.domain import use_private_domain

    use_private_domain("stress.py")
    process = subprocess.Popen(
        [str(BIN / "stageros"), "--view-port", "0", "--bag", str(folder / "soak.mcap"), "rooms.world"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    url = _view_url(process)
    viewer = threading.Thread(target=lambda: asyncio.run(_watch_view(url, sizes.soak_s + 30)), daemon=True)
    viewer.start()
    rclpy.init()
    node = rclpy.create_node("stress")
    clock: list[float] = []
    node.create_subscription(Clock, "/clock", lambda m: clock.append(m.clock.sec + m.clock.nanosec * 1e-9), 1000)
    commands = node.create_publisher(Twist, "cmd_vel", 10)
    reset = node.create_client(Empty, "reset_positions")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    windows, memory = [], []
    try:
        while len(clock) < 3:
            executor.spin_once(timeout_sec=0.05)
        start = time.monotonic()
        window = (start, clock[-1])
        next_command = next_reset = start
        warmed = False
        twist = Twist()
        twist.linear.x, twist.angular.z = 0.5, 0.3
        while (now := time.monotonic()) - start < sizes.soak_s:
            while next_command <= now:  # 2 kHz of commands
                commands.publish(twist)
                next_command += 0.0005
            if next_reset <= now:  # ten resets a second, never waited for
                reset.call_async(Empty.Request())
                next_reset += 0.1
            executor.spin_once(timeout_sec=0.0005)
            if now - window[0] >= sizes.window_s:
                if warmed:  # the first window is the warm-up (kernels loading, the view connecting)
                    windows.append((clock[-1] - window[1]) / (now - window[0]))
                warmed = True
                memory.append(_rss_mb(process.pid))
                window = (now, clock[-1])
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
        process.send_signal(signal.SIGINT)
        process.wait(timeout=60)
    worst = max(abs(rate - 1.0) for rate in windows)
    growth = memory[-1] - memory[0] if len(memory) > 1 else 0.0
    return {"check": "soak", "wall_s": sizes.soak_s, "rates": [round(r, 3) for r in windows],
            "worst_rate_error_pct": round(100 * worst, 1), "rss_mb": [round(m, 1) for m in memory],
            "rss_growth_mb": round(growth, 1), "exit_status": process.returncode,
            "ok": worst <= 0.05 and growth <= max(10.0, 0.05 * memory[0])}


def _view_url(process: subprocess.Popen) -> str:
    for line in process.stdout:
        if line.startswith("view: http"):
            return line.split()[1].replace("http://", "ws://").rstrip("/") + "/ws"
    raise RuntimeError("stageros ended before serving its view")


async def _watch_view(url: str, seconds: float) -> None:
    """A page that keeps reading the view's frames."""
    import aiohttp

    async with aiohttp.ClientSession() as session, session.ws_connect(url) as socket:
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline and not socket.closed:
            await socket.receive(timeout=seconds)


def _rss_mb(pid: int) -> float:
    """Resident memory of ``pid`` and its children (stageros and its bag writer)."""
    total = 0.0
    for process in (pid, *_children(pid)):
        for line in Path(f"/proc/{process}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                total += int(line.split()[1]) / 1024
    return total


CHECKS = {"frozen": check_frozen, "concurrent": check_concurrent, "complete": check_complete, "kill9": check_kill9,
          "soak": check_soak}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny sizes: a check of the checks (make test)")
    parser.add_argument("--checks", nargs="+", choices=CHECKS, default=list(CHECKS))
    args = parser.parse_args(argv)
    sizes = QUICK if args.quick else FULL
    failed = False
    with tempfile.TemporaryDirectory() as folder:
        for name in args.checks:
            result = CHECKS[name](sizes, Path(folder))
            print(json.dumps(result), flush=True)
            failed |= not result["ok"]
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
