"""The live browser view: a page that shows the simulation as Stage's window does and lets you move it.

:class:`LiveView` serves it (aiohttp, on its own thread) for one simulation whose host implements
:class:`Controls`; the host calls :meth:`LiveView.service` between steps. :class:`PacedLoop` is such a host
for core-only runs (``stage_sim view``). Nothing here imports ROS; aiohttp is imported only when a view is
built, so the command-line options cost nothing.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

_EXPORTS = {
    "Controls": "stage_sim.view.live",
    "LiveView": "stage_sim.view.live",
    "PacedLoop": "stage_sim.view.loop",
    "DEFAULT_PORT": "stage_sim.view.options",
    "ViewSettings": "stage_sim.view.options",
    "add_view_arguments": "stage_sim.view.options",
    "view_settings": "stage_sim.view.options",
}
__all__ = [
    "DEFAULT_PORT", "Controls", "LiveView", "PacedLoop", "ViewSettings", "add_view_arguments", "view_settings",
]

if TYPE_CHECKING:
    from stage_sim.view.live import Controls, LiveView
    from stage_sim.view.loop import PacedLoop
    from stage_sim.view.options import DEFAULT_PORT, ViewSettings, add_view_arguments, view_settings


def __getattr__(name: str) -> Any:
    if name not in _EXPORTS:
        raise AttributeError(f"module 'stage_sim.view' has no attribute {name!r}")
    return getattr(importlib.import_module(_EXPORTS[name]), name)
