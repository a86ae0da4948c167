"""Record a running simulation as an animated GIF (every frame) or a PNG (the last frame).

Usage, by any loop that steps a :class:`~stage_sim.sim.simulation.Simulation`::

    recorder = Recorder(sim, "run.gif", every_s=0.5)   # captures the current state as the first frame
    while running:
        sim.step()
        recorder.capture_if_due()                        # cheap: a pose copy, a snapshot when a frame is due
    recorder.close()                                     # draws the frames and writes the file

Drawing a frame costs milliseconds while a step of a Stage world costs about one, so frames are not drawn
while the simulation runs: ``capture_if_due`` keeps a :class:`~stage_sim.rendering.frame.Snapshot` (poses
and scans) every ``every_s`` sim seconds and each step's poses for the trails, and :meth:`Recorder.close`
draws and writes everything. That keeps the recording overhead a few percent of the stepping time. A GIF
holds all its frames in memory while it is written (about width × height bytes each).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from PIL import Image

from stage_sim.rendering.frame import Snapshot, renderer_for
from stage_sim.sim.simulation import Simulation

FORMATS = (".gif", ".png")

GIF_PALETTE_SAMPLES = 8
"""Frames, evenly spread over the run, whose colours make the GIF's shared palette."""


class Recorder:
    """Frames of ``sim`` every ``every_s`` sim seconds, written to ``path`` by :meth:`close`.

    ``path`` ending in ``.gif``: an animation of every frame, played at ``fps`` frames per second
    (default: real time, 1 / ``every_s``), looping. ``.png``: only the last frame. The first frame is the
    state at construction; :meth:`close` adds the final state unless it is the last frame already, so a run
    of D sim seconds gives D / ``every_s`` + 1 frames when D is a multiple of ``every_s``. Each frame shows the last
    ``trail_s`` sim seconds of every robot's path (0: no trails); ``scale``, ``lasers`` and ``grid`` are
    :meth:`Simulation.render`'s options.
    """

    def __init__(
        self,
        sim: Simulation,
        path: str | Path,
        every_s: float = 0.5,
        fps: float | None = None,
        trail_s: float = 10.0,
        *,
        scale: float | None = None,
        lasers: bool = True,
        grid: bool = False,
    ) -> None:
        self.path = Path(path)
        if self.path.suffix.lower() not in FORMATS:
            raise ValueError(f"can only record to {' or '.join(FORMATS)} files, not '{self.path.name}'")
        if not every_s > 0 or not (fps is None or fps > 0) or not trail_s >= 0:
            raise ValueError(f"need every_s > 0, fps > 0 and trail_s >= 0 (got {every_s}, {fps}, {trail_s})")
        self.sim = sim
        self.fps = fps if fps is not None else 1.0 / every_s
        self._options = {"scale": scale, "lasers": lasers, "grid": grid}
        renderer_for(sim).view(scale)  # a bad scale fails now, not after the run
        self._animate = self.path.suffix.lower() == ".gif"
        self._every_us = max(1, round(every_s * 1_000_000))
        self._trail_us = round(trail_s * 1_000_000)
        self._max_speed = np.array([_max_speed(r.settings.velocity_bounds) for r in sim.robots])
        self._times: list[int] = []
        self._poses: list[np.ndarray] = []
        self._trail_start = 0
        # A frame: its snapshot and the slice of the pose history its trails are drawn from.
        self._frames: list[tuple[Snapshot, int, int]] = []
        self._next_us = self._last_us = sim.sim_time_us
        self.capture_if_due()

    @property
    def frame_count(self) -> int:
        """Frames captured so far (a PNG keeps only the last)."""
        return len(self._frames)

    def capture_if_due(self) -> bool:
        """Note the robots' poses and, when a frame is due, keep a snapshot. Call it after every step."""
        now = self.sim.sim_time_us
        if now < self._last_us:  # the simulation was reset: frames and trails start afresh from here
            self._next_us = now
            self._trail_start = len(self._times)
        self._last_us = now
        if self._trail_us > 0 and not (self._times and self._times[-1] == now):
            self._times.append(now)
            self._poses.append(self.sim.true_poses.copy())
        if now < self._next_us:
            return False
        while self._trail_start < len(self._times) and self._times[self._trail_start] < now - self._trail_us:
            self._trail_start += 1
        if not self._animate:  # only the last frame is kept, and only its part of the pose history
            del self._times[: self._trail_start], self._poses[: self._trail_start]
            self._trail_start = 0
            self._frames.clear()
        self._frames.append((Snapshot.of(self.sim), self._trail_start, len(self._times)))
        self._next_us += self._every_us * ((now - self._next_us) // self._every_us + 1)
        return True

    def close(self) -> Path:
        """Capture the final state (if not the last frame already), draw every frame and write the file."""
        if self._frames[-1][0].sim_time != self.sim.sim_time:
            self._next_us = self.sim.sim_time_us
            self.capture_if_due()
        renderer = renderer_for(self.sim)
        times = np.array(self._times, dtype=np.int64)
        poses = np.array(self._poses).reshape(len(self._times), len(self.sim.robots), 3)

        def draw(frame: tuple[Snapshot, int, int]) -> Image.Image:
            snapshot, start, end = frame
            return renderer.image(snapshot, trails=self._trails(times[start:end], poses[start:end]), **self._options)

        if not self._animate:
            draw(self._frames[-1]).save(self.path)
            return self.path
        # One palette for all frames, from a sample of them: Pillow's own per-frame quantisation would take
        # ten times longer than drawing, and paletted frames hold a third of the memory.
        sample = [draw(frame) for frame in self._frames[:: max(1, len(self._frames) // GIF_PALETTE_SAMPLES)]]
        montage = Image.new("RGB", (sample[0].width, sample[0].height * len(sample)))
        for k, image in enumerate(sample):
            montage.paste(image, (0, k * image.height))
        shared = montage.quantize(method=Image.Quantize.FASTOCTREE)
        images = [draw(frame).quantize(palette=shared, dither=Image.Dither.NONE) for frame in self._frames]
        duration = max(1, round(1000 / self.fps))
        images[0].save(self.path, save_all=True, append_images=images[1:], duration=duration, loop=0)
        return self.path

    def _trails(self, times: np.ndarray, poses: np.ndarray) -> list[np.ndarray] | None:
        """Per robot the xy path of ``poses`` (T, N, 3), broken (NaN row) where a robot jumped farther than
        its velocity bounds allow, i.e. a ``reset_positions`` put it back at its start."""
        if self._trail_us == 0:
            return None
        path = poses[:, :, :2]
        allowed = self._max_speed[None, :] * np.diff(times)[:, None] / 1e6 * 1.01 + 1e-9
        jumped = np.linalg.norm(np.diff(path, axis=0), axis=2) > allowed
        trails = []
        for robot in range(path.shape[1]):
            breaks = np.flatnonzero(jumped[:, robot]) + 1
            trails.append(np.insert(path[:, robot], breaks, np.nan, axis=0))
        return trails


def _max_speed(bounds: tuple[float, ...]) -> float:
    """Fastest translation the velocity bounds (xmin, xmax, ymin, ymax, ...) allow."""
    return math.hypot(max(abs(bounds[0]), abs(bounds[1])), max(abs(bounds[2]), abs(bounds[3])))
