"""``stage_sim recover BROKEN.mcap [-o FIXED.mcap]``: a complete bag from one that was cut short (kill -9).

Exit status 0 when messages were recovered, 1 when none could be (no output is written), 2 for bad input
(unreadable or not an MCAP file, or an output path that is the input itself).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any


def run(args: argparse.Namespace) -> int:
    from stage_sim.bags.errors import BagError
    from stage_sim.bags.recover import NothingRecovered, recover

    source: Path = args.bag
    target: Path = args.output or source.with_name(f"{source.stem}.recovered.mcap")
    try:
        result = recover(source, target)
    except NothingRecovered as exc:
        print(f"stage_sim recover: {exc}; nothing written", file=sys.stderr)
        return 1
    except BagError as exc:
        print(f"stage_sim recover: {exc}", file=sys.stderr)
        return 2
    until = "" if result.last_log_time_ns is None else f" up to sim time {result.last_log_time_ns / 1e9:g} s"
    how = "the file was complete" if result.stopped_at is None else f"the rest was cut ({result.stopped_at})"
    print(f"{target}: {result.messages} messages{until}; {how}")
    return 0


def add_command(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "recover", help="rewrite a bag cut short (kill -9, full disk) into a complete, indexed MCAP file",
        description="Copy every record of an MCAP file that reads completely (up to its last whole chunk) into a "
        "new file with a fresh index, as 'mcap recover' does. The input is never written to.",
        epilog="exit status: 0 messages recovered, 1 none could be (nothing written), 2 bad input")
    parser.add_argument("bag", type=Path, help="the cut-short .mcap file")
    parser.add_argument("-o", "--output", type=Path, help="the new file, not the input (default: BAG.recovered.mcap)")
    parser.set_defaults(run=run)
