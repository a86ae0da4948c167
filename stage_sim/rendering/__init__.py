"""Pictures of a simulation with Pillow: frames as arrays or images, and recordings as PNG or GIF.

Nothing in the core imports this package, so the core runs without Pillow.
"""

from stage_sim.rendering.frame import FrameRenderer, Snapshot, View, render, renderer_for
from stage_sim.rendering.recorder import Recorder

__all__ = ["FrameRenderer", "Recorder", "Snapshot", "View", "render", "renderer_for"]
