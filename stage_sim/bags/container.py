"""The MCAP file of a bag, laid out as ``ros2 bag record -s mcap`` (Jazzy) writes one, via the ``mcap`` library.

Profile ``ros2``; one schema per message type (``ros2msg`` encoding: the definition with its dependencies,
as rosbag2 embeds it); one channel per topic (``cdr``) whose metadata holds ``offered_qos_profiles`` and
``topic_type_hash``; a ``rosbag2`` metadata record saying the bag is of metadata version 9 (string QoS
enums), written first so that a file cut short (kill -9) still says so after ``stage_sim recover``.

Chunks are zstd-compressed and flushed to the operating system as soon as the library completes one, so
after a kill -9 everything up to the last completed chunk is on disk. A recording paced to the wall clock
also closes a chunk once it spans a wall second's worth of sim time (CHUNK_WALL_SECONDS × speedup), so a kill -9
loses about a second of it; a run that is not paced closes chunks by size only (a chunk a sim second would cost
it more than the writing, and its wall seconds hold many chunks anyway). Closing by sim time, not by the wall
clock, keeps a recording's bytes the same from run to run.
"""

from __future__ import annotations

import contextlib
from io import BufferedWriter
from pathlib import Path

from mcap.writer import CompressionType, Writer
from rosbags.typesys.store import Typestore

from stage_sim.bags.errors import BAG_SUFFIX, BagError
from stage_sim.bags.topics import Topic, yaml_text

CHUNK_BYTES = 1024 * 1024
"""Uncompressed bytes per chunk at most (the mcap and rosbag2 default)."""
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


class McapBag:
    """An open bag: register the topics once, then :meth:`write` messages; :meth:`finish` writes the index."""

    def __init__(self, path: Path, topics: list[Topic], typestore: Typestore, library: str,
                 speedup: float = 0.0) -> None:
        """Create ``path`` (replacing a file there) and write everything but the messages; ``speedup`` is the
        run's (``<= 0``: not paced, chunks close by size only).

        Raises BagError when the file cannot be created or written (missing folder, no permission, full disk)
        or does not end in .mcap."""
        self.path = path
        if path.suffix != BAG_SUFFIX:
            raise BagError(f"bag {path} must end in {BAG_SUFFIX} (readers choose the format by that suffix)")
        try:
            self._stream: BufferedWriter = open(path, "wb")  # noqa: SIM115 - closed by finish()/abort()
        except OSError as exc:
            raise BagError(f"cannot write bag {path}: {exc.strerror or exc}") from None
        self._writer = Writer(self._stream, chunk_size=CHUNK_BYTES, compression=CompressionType.ZSTD)
        self._channels: dict[str, int] = {}
        try:
            self._writer.start(profile=PROFILE, library=library)
            self._writer.add_metadata("rosbag2", {"serialized_metadata": _rosbag2_metadata(path)})
            schemas: dict[str, int] = {}
            for topic in topics:
                if topic.msgtype not in schemas:
                    text, _ = typestore.generate_msgdef(topic.msgtype, ros_version=2)
                    schemas[topic.msgtype] = self._writer.register_schema(topic.msgtype, "ros2msg", text.encode())
                metadata = {"offered_qos_profiles": topic.offered_qos_profiles(),
                            "topic_type_hash": typestore.hash_rihs01(topic.msgtype)}
                self._channels[topic.name] = self._writer.register_channel(
                    topic.name, "cdr", schemas[topic.msgtype], metadata)
            self._stream.flush()
        except OSError as exc:
            self.abort()
            raise BagError(f"cannot write bag {path}: {exc.strerror or exc}") from None
        self._written = self._stream.tell()
        self._chunk_start_ns: int | None = None
        self._chunk_span_ns = round(CHUNK_WALL_SECONDS * speedup * 1e9) if speedup > 0 else None

    def write(self, topic: str, log_time_ns: int, data: bytes) -> None:
        """Add one message (log and publish time = its sim stamp); raises OSError when the disk refuses."""
        self._writer.add_message(self._channels[topic], log_time_ns, data, log_time_ns)
        if self._stream.tell() != self._written:  # the library has just completed a chunk: hand it to the OS
            self._stream.flush()
            self._written = self._stream.tell()
            self._chunk_start_ns = None
        elif self._chunk_span_ns is None:
            return
        elif self._chunk_start_ns is None:
            self._chunk_start_ns = log_time_ns
        elif log_time_ns - self._chunk_start_ns >= self._chunk_span_ns:
            self.flush()

    def flush(self) -> None:
        """Close the open chunk and hand everything to the operating system (survives a kill -9 from now on)."""
        self._writer.flush()
        self._written = self._stream.tell()
        self._chunk_start_ns = None

    def finish(self, metadata: dict[str, str] | None = None) -> None:
        """Write the last chunk, ``metadata`` (a ``stage_sim`` record), the summary and the footer; close."""
        try:
            if metadata:
                self._writer.add_metadata("stage_sim", metadata)
            self._writer.finish()
        finally:
            self._stream.close()

    def abort(self) -> None:
        """Close without a summary (after a write error): what reached the disk stays readable."""
        with contextlib.suppress(OSError):
            self._stream.close()
