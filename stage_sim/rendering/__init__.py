"""Pictures of a simulation with Pillow: frames as arrays or images, and recordings as PNG or GIF.

The core imports this package lazily (from :meth:`Simulation.render`), so it runs without it.
"""

from stage_sim.rendering.frame import FrameRenderer, Snapshot, View, render_frame, renderer_for
from stage_sim.rendering.recorder import Recorder

__all__ = ["FrameRenderer", "Recorder", "Snapshot", "View", "render_frame", "renderer_for"]
