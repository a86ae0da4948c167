"""The environments' ``rgb_array`` frame: the renderer's picture of the world with every goal marked.

Goals are drawn as crosses in their robot's colour, so a viewer sees who heads where.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from stage_sim.rendering import palette, render, renderer_for
from stage_sim.sim.simulation import Simulation

#: Half the size of a goal cross, in metres.
GOAL_MARK = 0.15


def picture(sim: Simulation, goals: np.ndarray, agents: list[int]) -> np.ndarray:
    """An (H, W, 3) uint8 frame of ``sim`` with a cross at each goal (goal k belongs to robot ``agents[k]``)."""
    frame = Image.fromarray(render(sim))
    view = renderer_for(sim).view()
    draw = ImageDraw.Draw(frame)
    width = max(1, round(view.scale * 0.03))
    for agent, goal in zip(agents, np.asarray(goals).reshape(-1, 2), strict=True):
        ink = palette.blend(sim.robots[agent].model.color)
        for dx, dy in ((1, 1), (1, -1)):
            ends = np.array([goal - GOAL_MARK * np.array([dx, dy]), goal + GOAL_MARK * np.array([dx, dy])])
            draw.line(view.continuous(ends).ravel().tolist(), fill=ink, width=width)
    return np.asarray(frame)
