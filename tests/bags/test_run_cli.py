"""``stage_sim run --bag`` as users run it, in its own process: no ROS, and no recording lost on the way out."""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap.records import Chunk
from mcap.stream_reader import StreamReader
from rosbags.highlevel import AnyReaderError

from stage_sim.bags.recover import UNREADABLE
from stage_sim.cli.controllers import CONTROLLERS
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world
from tests.bags.readers import READERS
from tests.bags.worlds import ROBOT_TOPICS, two_robot_world

pytestmark = pytest.mark.slow  # every test starts the console script

ROS_PACKAGES = ("rclpy", "builtin_interfaces", "geometry_msgs", "nav_msgs", "rosgraph_msgs", "sensor_msgs",
                "std_msgs", "tf2_msgs")
# Runs the console script's main() and fails (status 3) if anything of ROS was imported on the way.
NO_ROS_MAIN = (
    "import sys\n"
    "from stage_sim.cli import main\n"
    "status = main(sys.argv[1:])\n"
    f"ros = sorted(m for m in sys.modules if m.split('.')[0] in {ROS_PACKAGES!r})\n"
    "print('ROS modules imported:', ros, file=sys.stderr)\n"
    "sys.exit(3 if ros else status)\n"
)


def stage_sim(*args: str | Path, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", NO_ROS_MAIN, *map(str, args)], capture_output=True, text=True,
                          timeout=120, **kwargs)


def start(*args: str | Path, **kwargs) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "stage_sim.cli", *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kwargs)


def chunks_on_disk(path: Path) -> int:
    """How many whole chunks ``path`` holds (a writer may still be adding to it)."""
    count = 0
    with path.open("rb") as stream:
        try:
            for record in StreamReader(stream, emit_chunks=True).records:
                count += isinstance(record, Chunk)
        except UNREADABLE:  # the record being written
            pass
    return count


def wait_for_chunks(path: Path, chunks: int, process: subprocess.Popen, timeout_s: float = 60.0) -> None:
    """Until ``chunks`` whole chunks are on disk (the first holds the latched messages)."""
    deadline = time.monotonic() + timeout_s
    while not (path.exists() and chunks_on_disk(path) >= chunks):
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "the bag did not grow"
        time.sleep(0.05)


def test_kernels_and_threads_choose_how_a_run_is_computed_not_what_it_records(tmp_path) -> None:
    world = two_robot_world(tmp_path)
    env = {k: v for k, v in os.environ.items() if k not in ("STAGE_SIM_KERNELS", "STAGE_SIM_THREADS")}
    threads = max(1, len(os.sched_getaffinity(0)) - 1)
    bags = []
    for name, options, summary in (
            ("numpy", ["--kernels", "numpy", "--threads", "1"], "numpy kernels, 1 thread)"),
            ("numba", ["--kernels", "numba", "--threads", "2"], "numba kernels, 2 threads)"),
            # as fast as possible, nothing chosen: every core but the bag writer's
            ("unchosen", [], f"kernels, {threads} thread{'s' if threads > 1 else ''})")):
        (tmp_path / name).mkdir()
        bag_path = tmp_path / name / "run.mcap"  # the same name: the bag's metadata holds it
        result = stage_sim("run", world, "--duration", "2", "--speedup", "0", "--seed", "5", "--bag", bag_path,
                           *options, env=env)
        assert result.returncode == 0, result.stderr
        assert summary in result.stdout.splitlines()[0]
        bags.append(bag_path.read_bytes())
    assert bags[0] == bags[1] == bags[2]


def test_core_only_run_records_what_the_simulation_had_without_importing_ros(tmp_path) -> None:
    world = two_robot_world(tmp_path)
    bag_path = tmp_path / "run.mcap"
    result = stage_sim("run", world, "--duration", "2", "--speedup", "0", "--seed", "5", "--bag", bag_path)
    assert result.returncode == 0, result.stderr
    assert "ROS modules imported: []" in result.stderr
    assert f"bag {bag_path}: {1 + 20 * 12} messages" in result.stdout
    # The same run in this process: same world, seed and controller give the same steps.
    sim = Simulation(load_world(world), seed=5)
    drive = CONTROLLERS["straight"](sim, 5)
    first = None
    for _ in range(20):
        drive()
        sim.step()
        first = first or (sim.odometry_poses.copy(), [s.ranges.copy() for s in sim.scans[1]])
    for reader in READERS.values():
        bag = reader(bag_path)
        assert bag.counts() == {"/clock": 20, "/tf": 20, "/tf_static": 1} | {
            f"/robot_{i}/{topic}": 20 for i in range(2) for topic in ROBOT_TOPICS}
        for index, (odometry, scans) in ((0, first), (-1, (sim.odometry_poses, [s.ranges for s in sim.scans[1]]))):
            odom = bag.messages["/robot_1/odom"][index][1].pose.pose.position
            assert (odom.x, odom.y) == (odometry[1][0], odometry[1][1])
            for k, ranges in enumerate(scans):
                recorded = bag.messages[f"/robot_1/base_scan_{k}"][index][1].ranges
                np.testing.assert_array_equal(np.asarray(recorded, dtype=np.float32), ranges.astype(np.float32))


def test_quit_time_ends_the_run_with_a_complete_bag(tmp_path) -> None:
    bag_path = tmp_path / "quit.mcap"
    result = stage_sim("run", two_robot_world(tmp_path, quit_time=1.0), "--duration", "100", "--speedup", "0",
                       "--bag", bag_path, "--bag-topics", "/clock")
    assert result.returncode == 0, result.stderr
    assert READERS["mcap"](bag_path).counts() == {"/clock": 10}


def test_ctrl_c_finalises_the_bag(tmp_path) -> None:
    bag_path = tmp_path / "interrupted.mcap"
    process = start("run", two_robot_world(tmp_path), "--duration", "100000", "--speedup", "0", "--bag", bag_path)
    wait_for_chunks(bag_path, 2, process)  # the latched messages, then a first 1 MiB chunk
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 0, stderr
    assert "interrupted at sim time" in stderr and "Traceback" not in stderr
    for reader in READERS.values():  # complete: both readers open it as it is
        counts = reader(bag_path).counts()
        assert counts["/clock"] > 10 and counts["/robot_1/base_scan_1"] == counts["/clock"]


def writer_of(process: subprocess.Popen) -> int:
    """The process id of a run's bag writer (its only child)."""
    (pid,) = {int(child) for task in os.listdir(f"/proc/{process.pid}/task")
              for child in Path(f"/proc/{process.pid}/task/{task}/children").read_text().split()}
    return pid


def wait_until_gone(pid: int, timeout_s: float = 30.0) -> None:
    """Until process ``pid`` has ended (gone, or a zombie nobody reaps)."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            if Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z":
                return
        except FileNotFoundError:
            return
        assert time.monotonic() < deadline, f"process {pid} did not end"
        time.sleep(0.05)


def test_after_kill_9_of_the_simulator_its_writer_completes_the_bag(tmp_path) -> None:
    """The bag writer is a process of its own: the simulator killed, it writes every step it was sent and
    the summary, and says in the bag's metadata that the run was cut."""
    bag_path = tmp_path / "killed.mcap"
    process = start("run", two_robot_world(tmp_path), "--duration", "100000", "--speedup", "0", "--bag", bag_path)
    wait_for_chunks(bag_path, 2, process)  # the latched messages, then a first 1 MiB chunk
    writer = writer_of(process)
    process.kill()
    process.communicate()
    wait_until_gone(writer)
    for reader in READERS.values():  # complete: both readers open it as it is
        bag = reader(bag_path)
        clocks = [t for t, _ in bag.messages["/clock"]]
        assert len(clocks) > 100 and clocks == [100_000_000 * (i + 1) for i in range(len(clocks))]
        assert all(len(items) == len(clocks) for topic, items in bag.messages.items() if topic != "/tf_static")
    with bag_path.open("rb") as stream:
        (record,) = [m for m in make_reader(stream).iter_metadata() if m.name == "stage_sim"]
    assert record.metadata["interrupted"].startswith("the simulation ended without closing the bag after sim time")


def test_after_kill_9_of_both_the_bag_is_recovered_up_to_its_last_chunk(tmp_path) -> None:
    bag_path = tmp_path / "killed.mcap"
    process = start("run", two_robot_world(tmp_path), "--duration", "100000", "--speedup", "0", "--bag", bag_path,
                    start_new_session=True)
    wait_for_chunks(bag_path, 2, process)  # the latched messages, then a first 1 MiB chunk
    os.killpg(process.pid, signal.SIGKILL)
    process.communicate()
    with pytest.raises(AnyReaderError, match="end magic is invalid"):  # no footer: rosbags refuses the file
        READERS["rosbags"](bag_path)
    recovered = tmp_path / "killed.recovered.mcap"
    result = stage_sim("recover", bag_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(f"{recovered}: ") and "the rest was cut" in result.stdout
    for reader in READERS.values():
        bag = reader(recovered)
        clocks = [t for t, _ in bag.messages["/clock"]]
        assert len(clocks) > 100
        assert clocks == [100_000_000 * (i + 1) for i in range(len(clocks))]  # no step missing before the cut
        for topic, items in bag.messages.items():
            if topic != "/tf_static":
                assert len(clocks) - 1 <= len(items) <= len(clocks), topic  # the cut falls inside one step at most


def test_a_bag_that_cannot_be_created_is_an_error_before_the_run(tmp_path) -> None:
    full = tmp_path / "full.mcap"
    full.symlink_to("/dev/full")
    world = two_robot_world(tmp_path)
    for bag_path, message in ((tmp_path / "no" / "such" / "x.mcap", "No such file or directory"),
                              (full, "No space left on device"), (tmp_path / "x.bag", "must end in .mcap")):
        result = stage_sim("run", world, "--duration", "1", "--bag", bag_path)
        assert result.returncode == 2
        assert f"cannot write bag {bag_path}: {message}" in result.stderr or message in result.stderr
        assert "Traceback" not in result.stderr


def test_a_file_size_limit_below_the_writer_s_shared_memory_is_an_error_before_the_run(tmp_path) -> None:
    def small_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (10_000, 10_000))

    result = stage_sim("run", two_robot_world(tmp_path), "--duration", "1", "--bag", tmp_path / "x.mcap",
                       preexec_fn=small_files)
    assert result.returncode == 2
    assert "cannot make the memory the steps go to the bag writer in: File too large" in result.stderr
    assert "Traceback" not in result.stderr


def test_a_disk_that_fills_during_the_run_stops_it_with_a_message(tmp_path) -> None:
    bag_path = tmp_path / "filled.mcap"

    def limit_file_size() -> None:  # the disk "fills" at 1 MB (above the shared slots' size): after some chunks
        resource.setrlimit(resource.RLIMIT_FSIZE, (1_000_000, 1_000_000))

    result = stage_sim("run", two_robot_world(tmp_path), "--duration", "100000", "--speedup", "0", "--bag", bag_path,
                       preexec_fn=limit_file_size)
    assert result.returncode == 1
    assert f"cannot write bag {bag_path}: File too large at sim time" in result.stderr
    assert "recording stopped early" in result.stderr and "Traceback" not in result.stderr
    assert stage_sim("recover", bag_path).returncode == 0
    assert READERS["rosbags"](tmp_path / "filled.recovered.mcap").counts()["/clock"] > 10


def test_bag_options_need_a_bag(tmp_path) -> None:
    result = stage_sim("run", two_robot_world(tmp_path), "--duration", "1", "--bag-topics", "/clock")
    assert result.returncode == 2 and "give --bag OUT.mcap" in result.stderr

