"""The ``--record`` options shared by ``stageros`` and the launch scripts, and the recording they start.

Pillow and the renderer are imported only when a recording is asked for, so the nodes start without them.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from stage_sim.rendering.recorder import Recorder
    from stage_sim.ros.stageros import StageRos


def add_record_arguments(parser: argparse.ArgumentParser) -> None:
    """``--record OUT``, ``--record-every S`` and ``--record-fps F``."""
    parser.add_argument("--record", default=None, metavar="OUT",
                        help="record the run to OUT.gif (every frame) or OUT.png (the last frame) at exit")
    parser.add_argument("--record-every", type=float, default=0.5, metavar="S",
                        help="sim seconds between frames (default 0.5)")
    parser.add_argument("--record-fps", type=float, default=None, metavar="F",
                        help="GIF playback frames per second (default: real time)")


@contextlib.contextmanager
def recording(stage: StageRos, args: argparse.Namespace, prog: str) -> Iterator[Recorder | None]:
    """Capture ``stage``'s world after every step while the block runs, then write the file (also after
    Ctrl-C or an error) and say where on stderr; yields None when ``args.record`` is unset."""
    if not args.record:
        yield None
        return
    from stage_sim.rendering.recorder import Recorder

    recorder = Recorder(stage.sim, args.record, every_s=args.record_every, fps=args.record_fps)
    stage.add_step_listener(recorder.capture_if_due)
    try:
        yield recorder
    finally:
        print(f"{prog}: recorded {recorder.frame_count} frames to {recorder.close()}", file=sys.stderr)
