"""Rescue a bag that was cut short (kill -9, power loss, full disk): copy every readable record into a new file.

A bag whose writer never finished has no summary and no footer, which readers need (the Python ``mcap``
reader and rosbags both refuse such a file). The records before the cut are intact: the ``mcap`` stream
reader reads them in order, up to the last complete chunk, and the ``mcap`` writer writes them again with a
fresh index. ``mcap recover`` of the mcap command-line tool does the same, where it is installed.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from mcap.records import Channel, Header, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer

from stage_sim.bags.container import CHUNK_BYTES
from stage_sim.bags.errors import BagError


@dataclass(frozen=True)
class Recovered:
    """What the new file holds."""

    messages: int
    last_log_time_ns: int | None
    stopped_at: str | None
    """Why reading stopped before the end of the file (None: the file was complete)."""


def recover(source: Path, target: Path) -> Recovered:
    """Copy the readable records of ``source`` into a complete MCAP file ``target``.

    Raises BagError when ``source`` is not an MCAP file or ``target`` cannot be written."""
    try:
        reader_input = open(source, "rb")  # noqa: SIM115 - closed below
    except OSError as exc:
        raise BagError(f"cannot read {source}: {exc.strerror or exc}") from None
    try:
        with reader_input, open(target, "wb") as output:
            return _copy(StreamReader(reader_input), Writer(output, chunk_size=CHUNK_BYTES,
                                                            compression=CompressionType.ZSTD))
    except OSError as exc:
        raise BagError(f"cannot write {target}: {exc.strerror or exc}") from None


def _copy(reader: StreamReader, writer: Writer) -> Recovered:
    schemas: dict[int, int] = {}
    channels: dict[int, int] = {}
    messages, last_time, stopped_at = 0, None, None
    records = reader.records
    try:
        header = next(records)
    except Exception as exc:
        raise BagError(f"not an MCAP file: {exc}") from None
    if not isinstance(header, Header):
        raise BagError("not an MCAP file: it does not start with a header")
    writer.start(profile=header.profile, library=header.library)
    try:
        for record in records:
            if isinstance(record, Schema) and record.id not in schemas:  # the summary repeats them
                schemas[record.id] = writer.register_schema(record.name, record.encoding, record.data)
            elif isinstance(record, Channel) and record.id not in channels:
                channels[record.id] = writer.register_channel(
                    record.topic, record.message_encoding, schemas.get(record.schema_id, 0), record.metadata)
            elif isinstance(record, Message) and record.channel_id in channels:
                writer.add_message(channels[record.channel_id], record.log_time, record.data, record.publish_time,
                                   record.sequence)
                messages += 1
                last_time = record.log_time
            elif isinstance(record, Metadata):
                writer.add_metadata(record.name, record.metadata)
    except OSError:
        raise
    except Exception as exc:
        stopped_at = f"{type(exc).__name__}: {exc}"
    writer.finish()
    return Recovered(messages, last_time, stopped_at)
