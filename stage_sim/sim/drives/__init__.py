"""Drive models, one module per drive (``diff``, ``omni``, ``car``), found by the names the world file accepts.

The names live in :data:`stage_sim.worldfile.drive_names.DRIVE_NAMES` (world files are validated below the
simulation); the model of drive ``name`` is the module ``stage_sim.sim.drives.<name>``, which declares:

* ``HOLONOMIC``: whether it can move sideways (the wanderer then tries sideways commands too);
* ``STEERED``: whether its compiled twin reads the cos and sin of the command's angle (the others get none, and
  a step computes none for them);
* ``velocities(commands, wheelbases)``: the numpy reference, body velocities (vx, vy, va) for commands
  (gx, gy, ga) before ``velocity_bounds`` clamp them;
* ``compiled_velocities(commands, rows, wheelbases, cos_steer, sin_steer, out)``: its twin for numba, the same
  arithmetic for the robots ``rows`` written into ``out``. It is left undecorated so that this package imports
  without numba; :mod:`stage_sim.sim.motion_kernels` compiles it (cached beside the drive's module, so an edit
  recompiles it). ``cos_steer``/``sin_steer`` are numpy's cos/sin of ``commands[:, 2]`` (the compiled trig
  may differ from numpy's in the last bit).

Robots are stepped in one group per drive (:func:`group_by_drive`), so no compiled kernel dispatches on a drive.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from importlib import import_module

import numpy as np

from stage_sim.worldfile.drive_names import DRIVE_NAMES


@dataclass(frozen=True)
class Drive:
    """One drive model: what its module declares, under the name world files give it."""

    name: str
    holonomic: bool
    steered: bool
    velocities: Callable[[np.ndarray, np.ndarray], np.ndarray]
    compiled_velocities: Callable[..., None]


def _load(name: str) -> Drive:
    module = import_module(f"{__name__}.{name}")
    return Drive(name, module.HOLONOMIC, module.STEERED, module.velocities, module.compiled_velocities)


DRIVES: dict[str, Drive] = {name: _load(name) for name in DRIVE_NAMES}
"""Every drive model by world-file name, in :data:`DRIVE_NAMES` order."""


@dataclass(frozen=True)
class DriveGroup:
    """The robots of one drive: their indices (``rows``, int64) in the simulation's arrays."""

    drive: Drive
    rows: np.ndarray


class DriveGroups(tuple):
    """The drive groups of a world's robots (a tuple of :class:`DriveGroup`), knowing once whether any of them
    reads the steering angle: a step asks it of its commands, and asking the groups cost 0.3 µs a step."""

    steered: bool

    def __new__(cls, groups: Iterable[DriveGroup]) -> DriveGroups:
        made = super().__new__(cls, groups)
        made.steered = any(group.drive.steered for group in made)
        return made


@dataclass(frozen=True)
class DriveTable:
    """What turns a world's commands into body velocities: its robots' drive groups, wheelbases (N,) and
    ``velocity_bounds`` (N, 8) (a fused step reads them in its compiled call)."""

    groups: DriveGroups
    wheelbases: np.ndarray
    bounds: np.ndarray


def group_by_drive(names: Sequence[str]) -> DriveGroups:
    """The robots of each drive named in ``names`` (robot order), in registry order; absent drives get none."""
    names_array = np.array(names, dtype=object)
    groups = (DriveGroup(drive, np.flatnonzero(names_array == name).astype(np.int64)) for name, drive in DRIVES.items())
    return DriveGroups(group for group in groups if group.rows.size)
