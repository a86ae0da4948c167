"""Rescue a bag that was cut short (kill -9, power loss, full disk): copy every readable record into a new file.

A bag whose writer never finished has no summary and no footer, which readers need (the Python ``mcap``
reader and rosbags both refuse such a file). The records before the cut are intact: the ``mcap`` stream
reader reads them in order, up to the last complete chunk, and the ``mcap`` writer writes them again with a
fresh index. ``mcap recover`` of the mcap command-line tool does the same, where it is installed.

The input is only ever read: the copy goes to a temporary file beside the output, which is renamed into
place once the copy is complete and holds at least one message, so a failed or empty recovery leaves no
file behind and an existing output is replaced only by a good one.
"""

from __future__ import annotations

import os
import struct
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import zstandard
from mcap.exceptions import McapError
from mcap.records import Channel, Header, McapRecord, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer

from stage_sim.bags.container import CHUNK_BYTES
from stage_sim.bags.errors import BagError

UNREADABLE = (McapError, struct.error, zstandard.ZstdError, UnicodeDecodeError, OverflowError)
"""What the stream reader raises where a file is cut or damaged: the end of what can be recovered."""


class NothingRecovered(BagError):
    """The input is an MCAP file, but not one message of it could be read."""


@dataclass(frozen=True)
class Recovered:
    """What the new file holds."""

    messages: int
    last_log_time_ns: int | None
    stopped_at: str | None
    """Why reading stopped before the end of the file (None: the file was complete)."""


def recover(source: Path, target: Path) -> Recovered:
    """Copy the readable records of ``source`` into a complete MCAP file ``target``.

    Raises BagError when ``source`` cannot be read or is not an MCAP file, when ``target`` is ``source``
    itself (by any path or link) or cannot be written, and NothingRecovered when no message was readable."""
    _refuse_same_file(source, target)
    try:
        reader_input = open(source, "rb")  # noqa: SIM115 - closed below
    except OSError as exc:
        raise BagError(f"cannot read {source}: {exc.strerror or exc}") from None
    partial = None
    try:
        with reader_input, tempfile.NamedTemporaryFile(  # beside the target: the rename stays on one file system
                "wb", dir=target.parent, prefix=f".{target.name}.", suffix=".part", delete=False) as output:
            partial = Path(output.name)
            result = _copy(StreamReader(reader_input), Writer(output, chunk_size=CHUNK_BYTES,
                                                              compression=CompressionType.ZSTD))
        if result.messages == 0:
            raise NothingRecovered(f"no message of {source} could be read ({result.stopped_at or 'it holds none'})")
        os.replace(partial, target)
        partial = None
        return result
    except OSError as exc:
        raise BagError(f"cannot write {target}: {exc.strerror or exc}") from None
    finally:
        if partial is not None:
            partial.unlink(missing_ok=True)


def _refuse_same_file(source: Path, target: Path) -> None:
    """Writing over the input would destroy the only copy of what is being rescued."""
    try:
        same = target.exists() and source.exists() and os.path.samefile(source, target)
    except OSError:
        same = False
    if same or source.resolve() == target.resolve():
        raise BagError(f"the output {target} is the input {source}: choose another path with -o")


def _readable(reader: StreamReader, stop: list[str]) -> Iterator[McapRecord]:
    """The records of ``reader`` up to the first one that cannot be read (its reason appended to ``stop``)."""
    records = reader.records
    while True:
        try:
            record = next(records)
        except StopIteration:
            return
        except UNREADABLE as exc:
            stop.append(f"{type(exc).__name__}: {exc}")
            return
        yield record


def _copy(reader: StreamReader, writer: Writer) -> Recovered:
    schemas: dict[int, int] = {}
    channels: dict[int, int] = {}
    messages, last_time, stop = 0, None, []
    records = _readable(reader, stop)
    header = next(records, None)
    if not isinstance(header, Header):
        raise BagError(f"not an MCAP file ({stop[0] if stop else 'it does not start with an MCAP header'})")
    writer.start(profile=header.profile, library=header.library)
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
    writer.finish()
    return Recovered(messages, last_time, stop[0] if stop else None)
