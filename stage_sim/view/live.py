"""The simulation thread's side of the view: apply what pages asked for between steps, and sample frames.

Whoever steps the simulation (``stageros``' executor, ``stage_sim view``'s loop) calls
:meth:`LiveView.service` between steps, often (after every step, or on a ~30 Hz timer while paused). It
costs a clock read when nobody is watching and nothing was asked; a page's commands reach the simulation
only through the host's :class:`Controls`, the same paths its other inputs take (``cmd_vel``,
``reset_positions``), so the watchdog and every check still apply.
"""

from __future__ import annotations

import sys
import time
from typing import TYPE_CHECKING, Protocol

from stage_sim.view.frames import FrameSampler
from stage_sim.view.messages import Action, Drive, MessageReader, Pause, Place, Speed
from stage_sim.view.scene import Scene, robot_names
from stage_sim.view.server import ViewServer, ViewSettings

if TYPE_CHECKING:
    from stage_sim.runs.pacing import Pacer
    from stage_sim.sim.simulation import Simulation


class Controls(Protocol):
    """What a page may do, as the host of the simulation does it (called between steps only)."""

    pacer: Pacer
    """The run's schedule: whether it is paused and at what speedup (changed only through the methods below)."""

    def drive(self, robot: int, vx: float, vy: float, va: float) -> None:
        """A velocity command, exactly as one from ``cmd_vel``."""

    def reset_positions(self) -> None:
        """The ``reset_positions`` service."""

    def set_paused(self, paused: bool) -> None:
        """Stop or resume stepping (sim time stands still while paused)."""

    def set_speedup(self, speedup: float) -> None:
        """New real-time factor; ``<= 0`` is as fast as possible."""


class LiveView:
    """A :class:`ViewServer` bound to one simulation and its host's controls."""

    def __init__(
        self, sim: Simulation, controls: Controls, settings: ViewSettings | None = None,
        names: list[str] | None = None,
    ) -> None:
        self.sim = sim
        self.controls = controls
        self.settings = settings or ViewSettings()
        names = names or robot_names(sim)
        scene = Scene.of(sim, names, self.settings.readonly)
        self.server = ViewServer(scene, MessageReader(names, scene.bounds), self.settings)
        self.sampler = FrameSampler(sim)
        self._changed = False
        self.applied = 0
        """Page actions applied to the simulation since the start."""

    def start(self) -> str:
        """Serve, print ``view: URL`` once (and the warning an open bind deserves); returns the URL."""
        url = self.server.start()
        print(f"view: {url}", flush=True)
        if not self.settings.loopback and not self.settings.readonly:
            print(f"view: WARNING: serving on {self.settings.host}: anyone who can reach port {self.server.port} "
                  "can move and drive the robots (add --view-readonly to only show them)", file=sys.stderr, flush=True)
        return url

    def close(self) -> None:
        self.server.close()

    def service(self) -> None:
        """Apply the pages' pending actions, then send a frame if one is due and someone watches."""
        actions = self.server.actions
        while actions:
            self._apply(actions.popleft())
        if not self.server.viewers:
            return
        now = time.monotonic()
        if self.sampler.due(now):
            pacer = self.controls.pacer
            frame = self.sampler.take(now, pacer.paused, pacer.speedup, force=self._changed)
            self._changed = False
            if frame is not None:
                self.server.publish(frame)

    def _apply(self, action: Action) -> None:
        controls = self.controls
        if isinstance(action, Drive):
            controls.drive(action.robot, action.vx, action.vy, action.va)
        elif isinstance(action, Place):
            yaw = self.sim.true_poses[action.robot][2] if action.yaw is None else action.yaw
            self.sim.set_pose(action.robot, action.x, action.y, yaw)
        elif isinstance(action, Pause):
            controls.set_paused(action.paused)
        elif isinstance(action, Speed):
            controls.set_speedup(action.speedup)
        else:
            controls.reset_positions()
        self._changed = True
        self.applied += 1
