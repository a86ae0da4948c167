"""The MCAP file of a bag, laid out as ``ros2 bag record -s mcap`` (Jazzy) writes one, via foxglove-sdk's writer.

foxglove-sdk (``foxglove.open_mcap``) writes MCAP in Rust: chunking, zstd and the index cost the writer
thread a fraction of what the pure-Python ``mcap`` writer did (see docs/bags.md, "What recording costs").
Profile ``ros2``; one schema per message type (``ros2msg`` encoding: the definition with its dependencies,
as rosbag2 embeds it); one channel per topic (``cdr``) whose metadata holds ``offered_qos_profiles`` and
``topic_type_hash``; a ``rosbag2`` metadata record saying the bag is of metadata version 9 (string QoS
enums), written first so that a file cut short (kill -9) still says so after ``stage_sim recover``. The
library writes a channel (and its schema) just before its first message: a topic nothing was published on
is not in the bag.

Chunks are zstd-compressed (level 1: the writer shares the CPU with the simulation) and go to an unbuffered
file, so after a kill -9 everything up to the last completed chunk is on disk. A recording paced to the wall
clock also closes a chunk once it spans a wall second's worth of sim time (CHUNK_WALL_SECONDS × speedup), so a
kill -9 loses about a second of it; a run that is not paced closes chunks by size only (a chunk a sim second
would cost it more than the writing, and its wall seconds hold many chunks anyway). Closing by sim time, not by
the wall clock, keeps a recording's bytes the same from run to run.
"""

from __future__ import annotations

import contextlib
import os
from collections import deque
from collections.abc import Callable, Sequence
from itertools import chain, repeat
from operator import call
from pathlib import Path
from typing import Any, TypeVar

import foxglove
from foxglove.mcap import MCAPCompression, MCAPWriteOptions
from rosbags.typesys import Stores, get_typestore

from stage_sim.bags.errors import BAG_SUFFIX, BagError
from stage_sim.bags.topics import Topic, yaml_text

_T = TypeVar("_T")

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
"""ROS 2 Jazzy's message definitions: the schemas and type hashes a bag names, the serialiser of its messages."""

CHUNK_BYTES = 1024 * 1024
"""Uncompressed bytes per chunk at most (the mcap and rosbag2 default), for a bag of few topics."""
CHUNK_BYTES_PER_TOPIC = 10 * 1024
"""Uncompressed bytes per chunk per topic, for a bag of many: after each chunk the library writes a message
index per topic in it (a Python write and position query each), so a 100-robot bag (402 topics) in 1 MiB
chunks spent about a quarter of its writer's CPU on them; 4 MiB chunks hold about 11 of its steps."""
COMPRESSION_LEVEL = 1
"""zstd level of the chunks: the fastest, as the writer shares the CPU with the simulation (bags of scans
compress about as well at 1 as at the library's default, 3)."""
CHUNK_WALL_SECONDS = 1.0
"""Wall seconds (at the run's speedup) one chunk of a paced recording spans at most: what a kill -9 loses of a
slow recording (one robot at real time fills a 1 MiB chunk in about 28 s)."""
PROFILE = "ros2"
ROS_DISTRO = "jazzy"
METADATA_VERSION = 9


def _rosbag2_metadata(path: Path) -> str:
    """rosbag2's ``serialized_metadata``: which metadata version (and so QoS syntax) the channels use.

    rosbag2 rebuilds topics, counts and times from the MCAP summary; only the version, the distro and the
    storage identifier are read from here."""
    info = {
        "version": METADATA_VERSION,
        "storage_identifier": "mcap",
        "duration": {"nanoseconds": 0},
        "starting_time": {"nanoseconds_since_epoch": 0},
        "message_count": 0,
        "topics_with_message_count": [],
        "compression_format": "",
        "compression_mode": "",
        "relative_file_paths": [path.name],
        "files": [],
        "custom_data": {},
        "ros_distro": ROS_DISTRO,
    }
    return yaml_text(info)


class _File:
    """The bag's file as the Rust writer sees it. What the library writes during one of its calls is gathered
    and handed to the operating system in one write when the call returns (:meth:`commit`): after a chunk the
    library writes a small message index record per channel, each with a position query, which unbuffered cost
    a system call each (hundreds per chunk with 100 robots). Between calls nothing is held back, so a kill -9
    still finds everything up to the last completed chunk on disk. The first OSError (full disk, file size
    limit) is kept for :class:`McapBag` to raise, and from then on (and once closed) writes are dropped: the
    library would only print its own report of each, and the bag is over."""

    def __init__(self, path: Path) -> None:
        self._file = open(path, "wb", buffering=0)  # noqa: SIM115 - closed by close()
        self._pending = bytearray()
        self._position = 0
        """Where the next byte goes, counting the pending ones."""
        self.error: OSError | None = None

    def write(self, data: bytes | bytearray) -> int:
        if self.error is None and not self._file.closed:
            self._pending += data
            self._position += len(data)
        return len(data)

    def seek(self, offset: int, whence: int = 0) -> int:
        if self._file.closed:
            return 0
        if whence == os.SEEK_CUR and offset == 0:  # the library's "where am I" between records
            return self._position
        self.commit()
        self._position = self._file.seek(offset, whence)
        return self._position

    def commit(self) -> None:
        """Hand what the library's last call wrote to the operating system."""
        if self._pending and self.error is None and not self._file.closed:
            try:
                self._file.write(self._pending)
            except OSError as exc:
                self.error = exc
        self._pending.clear()

    def flush(self) -> None:
        """The library flushes at the end of a chunk: :meth:`commit`."""
        self.commit()

    def close(self) -> None:
        self.commit()
        self._file.close()


class McapBag:
    """An open bag: register the topics once, then :meth:`write` messages; :meth:`finish` writes the index."""

    def __init__(self, path: Path, topics: list[Topic], speedup: float = 0.0) -> None:
        """Create ``path`` (replacing a file there) and write its header and rosbag2 metadata; ``speedup`` is the
        run's (``<= 0``: not paced, chunks close by size only).

        Raises BagError when the file cannot be created or written (missing folder, no permission, full disk)
        or does not end in .mcap."""
        self.path = path
        if path.suffix != BAG_SUFFIX:
            raise BagError(f"bag {path} must end in {BAG_SUFFIX} (readers choose the format by that suffix)")
        try:
            self._file = _File(path)
        except OSError as exc:
            raise BagError(f"cannot write bag {path}: {exc.strerror or exc}") from None
        self._context = foxglove.Context()
        self._channels: dict[str, foxglove.Channel] = {}
        chunk = max(CHUNK_BYTES, CHUNK_BYTES_PER_TOPIC * len(topics))
        options = MCAPWriteOptions(profile=PROFILE, chunk_size=chunk, compression=MCAPCompression.Zstd,
                                   compression_level=COMPRESSION_LEVEL, compression_threads=0)
        try:
            self._writer = self._io(foxglove.open_mcap, self._file, context=self._context, writer_options=options)
            self._io(self._writer.write_metadata, "rosbag2", {"serialized_metadata": _rosbag2_metadata(path)})
        except OSError as exc:
            self.abort()
            raise BagError(f"cannot write bag {path}: {exc.strerror or exc}") from None
        schemas: dict[str, tuple[foxglove.Schema, str]] = {}
        """Per message type, once: its schema and its type hash."""
        for topic in topics:
            if topic.msgtype not in schemas:
                text, _ = TYPESTORE.generate_msgdef(topic.msgtype, ros_version=2)
                schemas[topic.msgtype] = (foxglove.Schema(name=topic.msgtype, encoding="ros2msg", data=text.encode()),
                                          TYPESTORE.hash_rihs01(topic.msgtype))
            schema, type_hash = schemas[topic.msgtype]
            metadata = {"offered_qos_profiles": topic.offered_qos_profiles(), "topic_type_hash": type_hash}
            self._channels[topic.name] = foxglove.Channel(topic.name, schema=schema,
                                                          message_encoding="cdr", context=self._context,
                                                          metadata=metadata)
        # The channels' own log(data, log_time), without the wrapper's checks for JSON and str messages.
        self._log = {name: channel.base.log for name, channel in self._channels.items()}
        self._chunk_start_ns: int | None = None
        self._chunk_span_ns = round(CHUNK_WALL_SECONDS * speedup * 1e9) if speedup > 0 else None

    def _io(self, call: Callable[..., _T], *args: Any, **kwargs: Any) -> _T:
        """``call`` of the library, whose failure to write (a RuntimeError) is raised as the file's OSError."""
        try:
            result = call(*args, **kwargs)
            self._file.commit()
        except RuntimeError:
            if self._file.error is None:
                raise
            raise self._file.error from None
        if self._file.error is not None:  # the library only logs a failed write of a chunk
            raise self._file.error
        return result

    def write(self, log_times_ns: Sequence[int], topics: Sequence[str], messages: Sequence[bytes | None]) -> None:
        """Add the messages (CDR bytes) of some steps: ``messages`` holds each step's in turn, one for each topic
        of ``topics`` (None: no message there), stamped (log and publish time) with the step's log time.
        Raises OSError when the disk refuses: the library reports that only when the chunk is written, so the
        batch from its first step on may be lost. A recording not paced logs the whole batch in one call
        (:func:`_log_each`); a paced one step by step, to close its chunks by sim time."""
        logs = [self._log[topic] for topic in topics]
        per_step = len(logs)
        if not per_step:  # a bag of latched topics only: the steps add nothing
            return
        span = self._chunk_span_ns
        if span is None:
            every_time = chain.from_iterable(zip(*repeat(log_times_ns, per_step), strict=True))  # per_step of each
            _log_each(logs * len(log_times_ns), messages, list(every_time))
        else:
            for at, log_time in zip(range(0, len(messages), per_step), log_times_ns, strict=True):
                _log_each(logs, messages[at:at + per_step], [log_time] * per_step)
                if self._chunk_start_ns is None:
                    self._chunk_start_ns = log_time
                elif log_time - self._chunk_start_ns >= span:
                    self.flush()
        self._file.commit()
        if self._file.error is not None:  # the library only logs a failed write of a chunk
            raise self._file.error

    def flush(self) -> None:
        """Close the open chunk and hand everything to the operating system (survives a kill -9 from now on);
        raises OSError when the disk refuses."""
        self._io(self._writer.flush)
        self._chunk_start_ns = None

    def finish(self, metadata: dict[str, str] | None = None) -> None:
        """Write the last chunk, ``metadata`` (a ``stage_sim`` record), the summary and the footer; close.
        Raises OSError when the disk refuses."""
        try:
            if metadata:
                self._io(self._writer.write_metadata, "stage_sim", metadata)
            self._io(self._writer.close)
        finally:
            self._close_channels()
            self._file.close()

    def abort(self) -> None:
        """Close without a summary (after a write error): what reached the disk stays readable."""
        self._close_channels()
        with contextlib.suppress(OSError):
            self._file.close()

    def _close_channels(self) -> None:
        for channel in self._channels.values():
            channel.close()
        self._channels = {}


def _log_each(logs: Sequence[Callable[[bytes, int], None]], messages: Sequence[bytes | None],
              log_times_ns: Sequence[int]) -> None:
    """``logs[i](messages[i], log_times_ns[i])`` for each message that is not None. The calls are made by C
    (map, drained by a deque that keeps nothing): a Python loop around them cost the writer process about a
    third as much CPU as the library's own work in them."""
    if None in messages:  # some rangers took no scan: rare (they are slower than the step)
        kept = [(log, data, time) for log, data, time in zip(logs, messages, log_times_ns, strict=True)
                if data is not None]
        logs, messages, log_times_ns = tuple(zip(*kept, strict=True)) if kept else ((), (), ())
    deque(map(call, logs, messages, log_times_ns), maxlen=0)
