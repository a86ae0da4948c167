"""A recorded run read back with both readers: every topic, type and count, the values the simulation had."""

from __future__ import annotations

import contextlib
import math
import os
import signal
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader

from stage_sim.bags.errors import BagError
from stage_sim.bags.recorder import BagRecorder
from stage_sim.interface.names import robot_names
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.loader import load_world
from tests.bags.readers import READERS, ReadBag
from tests.bags.worlds import two_robot_world

STEPS = 25
COMMANDS = [(0.3, 0.0, 0.2), (0.2, 0.0, -0.3)]


def names_of(sim: Simulation) -> list:
    return [robot_names(r.index, r.name, len(sim.robots), len(r.rangers)) for r in sim.robots]


@pytest.fixture(scope="module")
def recorded(tmp_path_factory) -> tuple[Path, list[dict]]:
    """25 steps of two robots driving arcs, recorded; and what the simulation had after each step."""
    folder = tmp_path_factory.mktemp("bag")
    sim = Simulation(load_world(two_robot_world(folder)), seed=3)
    path = folder / "run.mcap"
    recorder = BagRecorder(sim, path, names_of(sim))
    states = []
    for robot, command in enumerate(COMMANDS):
        sim.set_velocity(robot, *command)
    for _ in range(STEPS):
        sim.step()
        recorder.record_step()
        states.append({
            "time_us": sim.sim_time_us, "odom": sim.odometry_poses.copy(), "truth": sim.true_poses.copy(),
            "velocity": sim.velocities.copy(), "scans": [[s.ranges.copy() for s in robot] for robot in sim.scans],
        })
    summary = recorder.close()
    assert (summary.messages, summary.dropped_steps, summary.error) == (1 + STEPS * (2 + 2 * 5), 0, None)
    return path, states


@pytest.fixture(scope="module", params=sorted(READERS))
def bag(request, recorded) -> ReadBag:
    return READERS[request.param](recorded[0])


def stamp_ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def test_every_topic_with_its_type_and_one_message_per_step(bag) -> None:
    expected_types = {"/clock": "rosgraph_msgs/msg/Clock", "/tf": "tf2_msgs/msg/TFMessage",
                      "/tf_static": "tf2_msgs/msg/TFMessage"}
    for robot in ("robot_0", "robot_1"):
        expected_types |= {f"/{robot}/odom": "nav_msgs/msg/Odometry",
                           f"/{robot}/base_pose_ground_truth": "nav_msgs/msg/Odometry",
                           f"/{robot}/stall": "std_msgs/msg/Bool",
                           f"/{robot}/base_scan_0": "sensor_msgs/msg/LaserScan",
                           f"/{robot}/base_scan_1": "sensor_msgs/msg/LaserScan"}
    assert bag.types == expected_types
    assert bag.counts() == {topic: 1 if topic == "/tf_static" else STEPS for topic in expected_types}


def test_stamps_are_sim_time_and_increase_per_topic(bag, recorded) -> None:
    _, states = recorded
    step_times = [s["time_us"] * 1000 for s in states]
    for topic, items in bag.messages.items():
        log_times = [t for t, _ in items]
        if topic == "/tf_static":
            assert log_times == [0]
            continue
        assert log_times == step_times, topic
        for log_time, msg in items:
            if topic == "/clock":
                stamps = [msg.clock]
            elif topic == "/tf":
                stamps = [t.header.stamp for t in msg.transforms]
            else:  # std_msgs/Bool (stall) has no header: its log time is all there is
                stamps = [msg.header.stamp] if hasattr(msg, "header") else []
            assert all(stamp_ns(s) == log_time for s in stamps), topic


@pytest.mark.parametrize("index", [0, -1], ids=["first", "last"])
def test_scans_and_odometry_decode_to_the_simulated_values(bag, recorded, index) -> None:
    _, states = recorded
    state = states[index]
    for robot in range(2):
        prefix = f"/robot_{robot}"
        for ranger in range(2):
            _, scan = bag.messages[f"{prefix}/base_scan_{ranger}"][index]
            np.testing.assert_array_equal(np.asarray(scan.ranges, dtype=np.float32),
                                          state["scans"][robot][ranger].astype(np.float32))
            assert scan.header.frame_id == f"robot_{robot}/base_laser_link_{ranger}"
        for topic, pose, frame in (("odom", state["odom"][robot], f"robot_{robot}/odom"),
                                   ("base_pose_ground_truth", state["truth"][robot], "world")):
            _, odom = bag.messages[f"{prefix}/{topic}"][index]
            assert (odom.header.frame_id, odom.child_frame_id) == (frame, f"robot_{robot}/base_footprint")
            position, orientation = odom.pose.pose.position, odom.pose.pose.orientation
            assert (position.x, position.y) == (pose[0], pose[1])
            assert math.atan2(orientation.z, orientation.w) * 2 == pytest.approx(pose[2], abs=1e-12)
            twist = odom.twist.twist
            assert (twist.linear.x, twist.angular.z) == pytest.approx(COMMANDS[robot][::2])


def test_scan_geometry_is_the_rangers(bag) -> None:
    _, back = bag.messages["/robot_1/base_scan_1"][0]
    assert back.angle_min == pytest.approx(-math.radians(45), rel=1e-6)
    assert back.angle_increment == pytest.approx(math.radians(90) / 30, rel=1e-6)
    assert (back.range_min, back.range_max) == pytest.approx((0.1, 3.0))
    assert len(back.ranges) == 31


def test_tf_carries_every_robot_and_tf_static_every_fixed_frame(bag, recorded) -> None:
    _, states = recorded
    _, tf = bag.messages["/tf"][-1]
    assert [(t.header.frame_id, t.child_frame_id) for t in tf.transforms] == [
        ("robot_0/odom", "robot_0/base_footprint"), ("robot_1/odom", "robot_1/base_footprint")]
    assert tf.transforms[1].transform.translation.x == states[-1]["odom"][1][0]
    _, static = bag.messages["/tf_static"][0]
    edges = {(t.header.frame_id, t.child_frame_id): t.transform for t in static.transforms}
    assert set(edges) == {(f"robot_{i}/{a}", f"robot_{i}/{b}") for i in range(2) for a, b in (
        ("base_footprint", "base_link"), ("base_link", "base_laser_link_0"), ("base_link", "base_laser_link_1"))}
    back = edges[("robot_0/base_link", "robot_0/base_laser_link_1")]
    assert back.translation.x == pytest.approx(-0.2)
    assert (back.rotation.z, back.rotation.w) == pytest.approx((1.0, 0.0), abs=1e-12)


def test_tf_static_is_offered_transient_local_as_rosbag2_records_it(bag) -> None:
    qos = bag.qos["/tf_static"]
    if isinstance(qos, str):  # the mcap reader gives the channel metadata text rosbag2 wrote
        (profile,) = yaml.safe_load(qos)
        assert (profile["durability"], profile["reliability"], profile["history"], profile["depth"]) == (
            "transient_local", "reliable", "keep_last", 1)
        assert yaml.safe_load(bag.qos["/clock"])[0]["durability"] == "volatile"
    else:  # rosbags parses it
        (profile,) = qos
        assert (profile.durability.name, profile.reliability.name, profile.depth) == ("TRANSIENT_LOCAL", "RELIABLE", 1)
        assert bag.qos["/clock"][0].durability.name == "VOLATILE"


def test_bag_topics_records_only_those(tmp_path) -> None:
    sim = Simulation(load_world(two_robot_world(tmp_path)), seed=1)
    recorder = BagRecorder(sim, tmp_path / "some.mcap", names_of(sim), topics=["/clock", "robot_1/base_scan_0"])
    for _ in range(3):
        sim.step()
        recorder.record_step()
    recorder.close()
    assert READERS["rosbags"](tmp_path / "some.mcap").counts() == {"/clock": 3, "/robot_1/base_scan_0": 3}


def test_map_is_recorded_once_when_asked(tmp_path) -> None:
    """Also when the steps taken meanwhile publish nothing the bag records (no per-step topic in it)."""
    sim = Simulation(load_world(two_robot_world(tmp_path)), seed=1)
    recorder = BagRecorder(sim, tmp_path / "map.mcap", names_of(sim), topics=["/map"], with_map=True)
    for _ in range(3):
        sim.step()
        recorder.record_step()
    assert recorder.close().complete
    assert READERS["rosbags"](tmp_path / "map.mcap").counts() == {"/map": 1}
    ((log_time, grid),) = READERS["mcap"](tmp_path / "map.mcap").messages["/map"]
    expected = sim.static.to_occupancy_grid()
    assert (log_time, grid.header.frame_id, grid.info.width, grid.info.height) == (
        0, "world", expected.width, expected.height)
    assert bytes(np.asarray(grid.data, dtype=np.int8)) == expected.values.astype(np.int8).tobytes()


def test_unknown_topic_and_unwritable_path_are_errors_before_any_step(tmp_path) -> None:
    sim = Simulation(load_world(two_robot_world(tmp_path)), seed=1)
    with pytest.raises(ValueError, match=r"no such topic /robot_2/odom; .* /robot_1/odom"):
        BagRecorder(sim, tmp_path / "x.mcap", names_of(sim), topics=["/robot_2/odom"])
    with pytest.raises(BagError, match=r"cannot write bag .*missing/x\.mcap: No such file or directory"):
        BagRecorder(sim, tmp_path / "missing" / "x.mcap", names_of(sim))
    with pytest.raises(BagError, match=r"must end in \.mcap"):
        BagRecorder(sim, tmp_path / "x.bag", names_of(sim))


@contextlib.contextmanager
def writer_paused(pid: int, seconds: float) -> Iterator[None]:
    """The writer process stopped (SIGSTOP, as a starved or swapped-out process is) for ``seconds``, or until
    the block ends."""
    def resume() -> None:
        with contextlib.suppress(ProcessLookupError):  # it may have ended since
            os.kill(pid, signal.SIGCONT)

    os.kill(pid, signal.SIGSTOP)
    timer = threading.Timer(seconds, resume)
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
        resume()


def small_queue(monkeypatch: pytest.MonkeyPatch) -> None:
    """Batches of one step, a real-time recording in the fewest slots (two); a lossless one has four."""
    monkeypatch.setattr("stage_sim.bags.recorder.SLOTS_BYTES", 0)
    monkeypatch.setattr("stage_sim.bags.recorder.BATCH_STEPS", 1)


def test_a_lossless_recording_waits_for_a_stalled_writer_and_records_every_step(tmp_path, monkeypatch) -> None:
    small_queue(monkeypatch)
    sim = Simulation(load_world(two_robot_world(tmp_path)), seed=1)
    path = tmp_path / "slow.mcap"
    recorder = BagRecorder(sim, path, names_of(sim), speedup=0.0)
    start = time.monotonic()
    with writer_paused(recorder.writer_pid, 1.0):
        for _ in range(300):
            sim.step()
            recorder.record_step()
        waited = time.monotonic() - start
    summary = recorder.close()
    assert waited >= 0.9  # the simulation waited for the writer
    assert (summary.dropped_steps, summary.messages, summary.complete) == (0, 1 + 300 * 12, True)
    assert READERS["mcap"](path).counts()["/clock"] == 300


def test_a_stalled_writer_at_real_time_drops_steps_instead_of_stalling_and_the_bag_says_so(
        tmp_path, monkeypatch) -> None:
    small_queue(monkeypatch)
    sim = Simulation(load_world(two_robot_world(tmp_path)), seed=1)
    path = tmp_path / "slow.mcap"
    recorder = BagRecorder(sim, path, names_of(sim), speedup=1.0)
    longest = 0.0
    with writer_paused(recorder.writer_pid, 60.0):
        for _ in range(300):
            sim.step()
            start = time.perf_counter()
            recorder.record_step()
            longest = max(longest, time.perf_counter() - start)
    summary = recorder.close()
    assert summary.dropped_steps > 0 and longest < 0.05 and not summary.complete
    assert summary.messages + summary.dropped_messages == 1 + 300 * 12
    assert f"dropped {summary.dropped_messages} messages of {summary.dropped_steps} steps" in summary.describe()
    bag = READERS["mcap"](path)
    assert bag.counts()["/clock"] == 300 - summary.dropped_steps
    with path.open("rb") as stream:
        (record,) = [m for m in make_reader(stream).iter_metadata() if m.name == "stage_sim"]
    assert record.metadata == {"dropped_steps": str(summary.dropped_steps),
                               "dropped_messages": str(summary.dropped_messages)}


def test_the_writer_is_this_stage_sim_whatever_the_working_directory_holds(tmp_path, monkeypatch) -> None:
    """A recording started from a folder that holds another stage_sim (a checkout of another version) still
    gets a writer of its own code: the working directory is not first on the writer's path."""
    world = load_world(two_robot_world(tmp_path))
    other = tmp_path / "checkout" / "stage_sim"
    other.mkdir(parents=True)
    (other / "__init__.py").write_text('raise ImportError("the stage_sim of the working directory")\n')
    monkeypatch.chdir(other.parent)
    sim = Simulation(world, seed=1)
    recorder = BagRecorder(sim, tmp_path / "run.mcap", names_of(sim), speedup=0.0)
    for _ in range(3):
        sim.step()
        recorder.record_step()
    summary = recorder.close()
    assert summary.complete and READERS["mcap"](tmp_path / "run.mcap").counts()["/clock"] == 3


def test_a_writer_that_dies_ends_the_recording_with_a_message_and_the_run_goes_on(tmp_path) -> None:
    sim = Simulation(load_world(two_robot_world(tmp_path)), seed=1)
    recorder = BagRecorder(sim, tmp_path / "run.mcap", names_of(sim), speedup=0.0)
    os.kill(recorder.writer_pid, signal.SIGKILL)
    deadline = time.monotonic() + 10
    while not recorder.failed:
        sim.step()
        recorder.record_step()
        assert time.monotonic() < deadline
    summary = recorder.close()
    assert not summary.complete and "the bag writer process ended before the bag was complete" in summary.error
    assert "exited with status -9" in summary.error


@pytest.mark.parametrize(("speedup", "status"), [("0", 0), ("20", 1)])
def test_stage_sim_run_records_every_step_unless_paced_and_says_so_by_its_status(
        tmp_path, monkeypatch, capsys, speedup, status) -> None:
    """Unpaced (``--speedup 0``) the run waits for a stalled writer; paced to the wall clock it drops steps
    and exits 1, naming the cause."""
    from stage_sim.cli import main

    small_queue(monkeypatch)
    start = BagRecorder.__init__

    def stalled_start(self, *args, **kwargs) -> None:  # the writer stalls for 3 s (longer than the run)
        start(self, *args, **kwargs)
        stack.enter_context(writer_paused(self.writer_pid, 3.0))

    monkeypatch.setattr(BagRecorder, "__init__", stalled_start)
    path = tmp_path / "run.mcap"
    with contextlib.ExitStack() as stack:
        assert main(["run", str(two_robot_world(tmp_path)), "--duration", "40", "--speedup", speedup,
                     "--bag", str(path)]) == status
    clocks = READERS["mcap"](path).counts()["/clock"]
    if status == 0:
        assert clocks == 400
    else:
        assert clocks < 400 and "could not keep up" in capsys.readouterr().err
