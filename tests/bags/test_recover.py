"""``stage_sim recover`` cannot hurt: it never writes its input, leaves nothing behind when it fails, and says
(by its exit status) whether anything was recovered."""

from __future__ import annotations

import os
import signal
import struct
from pathlib import Path

import pytest

from stage_sim.bags.errors import BagError
from stage_sim.bags.recover import NothingRecovered, recover
from tests.bags.readers import READERS
from tests.bags.test_run_cli import stage_sim, start, wait_for_chunks
from tests.bags.worlds import two_robot_world


@pytest.fixture(scope="module")
def complete_bag(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    """The bytes of a 90 s two-robot recording (several chunks)."""
    folder = tmp_path_factory.mktemp("bag")
    bag = folder / "run.mcap"
    result = stage_sim("run", two_robot_world(folder), "--duration", "90", "--speedup", "0", "--bag", bag)
    assert result.returncode == 0, result.stderr
    return bag.read_bytes()


def header_only(data: bytes) -> bytes:
    """The magic, the header record and a few bytes of the next: an MCAP file cut before any message."""
    header_length = struct.unpack_from("<Q", data, 9)[0]  # magic (8 B), opcode (1 B), record length (8 B)
    return data[: 17 + header_length + 20]


def cut(folder: Path, data: bytes, fraction: float, name: str = "cut.mcap") -> Path:
    path = folder / name
    path.write_bytes(data[: int(len(data) * fraction)])
    return path


def test_output_equal_to_input_is_refused_and_the_input_kept(tmp_path, complete_bag) -> None:
    source = cut(tmp_path, complete_bag, 0.7)
    link = tmp_path / "link.mcap"
    link.symlink_to(source)
    hard = tmp_path / "hard.mcap"
    os.link(source, hard)
    for target in (source, Path(os.path.relpath(source)), link, hard):
        before = source.read_bytes()
        result = stage_sim("recover", source, "-o", target)
        assert result.returncode == 2, result.stderr
        assert "is the input" in result.stderr and "Traceback" not in result.stderr
        assert source.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cut.mcap", "hard.mcap", "link.mcap"]


def test_a_file_that_is_not_mcap_leaves_no_output(tmp_path) -> None:
    source = tmp_path / "notes.mcap"
    source.write_text("not a bag at all\n" * 100)
    result = stage_sim("recover", source)
    assert result.returncode == 2 and "not an MCAP file" in result.stderr, result.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["notes.mcap"]


def test_nothing_recovered_is_a_failure_and_writes_nothing(tmp_path, complete_bag) -> None:
    source = tmp_path / "start.mcap"
    source.write_bytes(header_only(complete_bag))
    result = stage_sim("recover", source)
    assert result.returncode == 1, result.stderr
    assert "no message" in result.stderr and "nothing written" in result.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["start.mcap"]
    with pytest.raises(NothingRecovered):
        recover(source, tmp_path / "out.mcap")


def test_an_existing_output_is_replaced_only_by_a_good_recovery(tmp_path, complete_bag) -> None:
    target = tmp_path / "out.mcap"
    target.write_bytes(b"previous result")
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(header_only(complete_bag))
    with pytest.raises(NothingRecovered):
        recover(empty, target)
    assert target.read_bytes() == b"previous result"
    result = recover(cut(tmp_path, complete_bag, 0.8), target)
    assert result.messages > 0 and result.stopped_at is not None
    assert READERS["rosbags"](target).counts()["/clock"] > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cut.mcap", "empty.mcap", "out.mcap"]


def test_a_complete_bag_is_copied_whole(tmp_path, complete_bag) -> None:
    source = tmp_path / "whole.mcap"
    source.write_bytes(complete_bag)
    result = recover(source, tmp_path / "copy.mcap")
    assert result.stopped_at is None
    assert READERS["rosbags"](tmp_path / "copy.mcap").counts() == READERS["rosbags"](source).counts()


@pytest.mark.parametrize("fraction", [0.5, 0.9, 0.999])
def test_a_cut_anywhere_recovers_what_was_before_it(tmp_path, complete_bag, fraction) -> None:
    result = recover(cut(tmp_path, complete_bag, fraction), tmp_path / "out.mcap")
    assert result.stopped_at is not None and result.messages > 0
    counts = READERS["mcap"](tmp_path / "out.mcap").counts()
    assert sum(counts.values()) == result.messages


def test_an_unwritable_output_is_a_clear_error(tmp_path, complete_bag) -> None:
    with pytest.raises(BagError, match="cannot write"):
        recover(cut(tmp_path, complete_bag, 0.5), tmp_path / "no" / "such" / "dir.mcap")


def test_a_kill_9_at_real_time_loses_about_a_second(tmp_path) -> None:
    """Chunks close after a sim second: a slow recording (two robots at real time fill a 1 MiB chunk in
    ~14 s) reaches the disk chunk after chunk within seconds, /tf_static first, and survives a kill -9 of the
    simulator and its bag writer both."""
    bag_path = tmp_path / "killed.mcap"
    process = start("run", two_robot_world(tmp_path), "--duration", "100000", "--speedup", "1", "--bag", bag_path,
                    start_new_session=True)
    try:
        wait_for_chunks(bag_path, 3, process, timeout_s=15.0)  # the latched messages, then two chunks of steps
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
    result = recover(bag_path, tmp_path / "out.mcap")
    bag = READERS["rosbags"](tmp_path / "out.mcap")
    assert len(bag.messages["/tf_static"]) == 1
    clocks = [t for t, _ in bag.messages["/clock"]]
    assert len(clocks) >= 5 and clocks == [100_000_000 * (i + 1) for i in range(len(clocks))]
    assert result.stopped_at is not None
