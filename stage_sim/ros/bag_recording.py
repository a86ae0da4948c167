"""``stageros --bag OUT.mcap [--bag-topics T ...]``: record what the node publishes into a ROS 2 bag.

No ``ros2 bag`` needed (it is not among the PyPI wheels): the ROS-free :class:`~stage_sim.bags.recorder.
BagRecorder` records the node's simulation after every step, with the node's names, namespace and /map
setting, so the bag holds what the node publishes (the same field values: :mod:`stage_sim.interface.fields`).
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from stage_sim.bags.errors import BagError

if TYPE_CHECKING:
    from stage_sim.bags.recorder import BagRecorder
    from stage_sim.ros.stageros import StageRos


def add_bag_arguments(parser: argparse.ArgumentParser) -> None:
    """``--bag OUT.mcap`` and ``--bag-topics T ...``."""
    parser.add_argument("--bag", type=Path, metavar="OUT.mcap",
                        help="record every published topic into a ROS 2 bag (MCAP), no 'ros2 bag' needed")
    parser.add_argument("--bag-topics", nargs="+", metavar="T",
                        help="record only these topics (e.g. /clock robot_0/base_scan; default: all)")


@contextlib.contextmanager
def bag_recording(stage: StageRos, args: argparse.Namespace, prog: str) -> Iterator[BagRecorder | None]:
    """Record ``stage`` after every step while the block runs, then finalise the bag (also after Ctrl-C or
    an error) and say what it holds on stderr (``recorder.summary`` then, for the exit status); lossless (the
    simulation waits for the writer) unless the node is paced to the wall clock. Yields None when ``args.bag``
    is unset. A bag that cannot be
    created raises BagError (a bad path) or ValueError (an unknown topic) before anything runs."""
    if not args.bag:
        yield None
        return
    try:
        from stage_sim.bags.recorder import BagRecorder
    except ImportError as error:  # a ROS install whose rosdep did not bring the bag libraries
        raise BagError(f"--bag needs the Python package '{error.name or error}' (pip install foxglove-sdk==0.30.3 "
                       "mcap mcap-ros2-support rosbags)") from error

    recorder = BagRecorder(stage.sim, args.bag, stage.names, namespace=stage.get_namespace(),
                           topics=args.bag_topics, with_map=stage.publish_map, prog=prog,
                           speedup=stage.pacer.speedup)
    stage.add_step_listener(recorder.record_step)
    try:
        yield recorder
    finally:
        print(f"{prog}: {recorder.close().describe()}", file=sys.stderr)
