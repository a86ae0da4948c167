"""The drives a world file may name (``drive "diff"``): the one list of them, and the registry of drive models.

Kept in the bottom layer because the world file is validated here, without the simulation; each name is also
the module that holds that drive's kinematics, :mod:`stage_sim.sim.drives.<name>`, and its position here is
nothing but the order of the registry. Adding a drive: write that module and add its name here.
"""

from __future__ import annotations

DRIVE_NAMES = ("diff", "omni", "car")
