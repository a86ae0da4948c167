"""The rays of a world's rangers grouped by height, as the sensing and a fused step cast them.

Rays are grouped by height because of Stage's 2.5D rule (:mod:`stage_sim.sim.rangers`); a world whose rays
all lie at one height and carry no noise is cast in one compiled call by a fused step
(:class:`~stage_sim.sim.compiled.FusedStep`), which needs the one group's tables.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stage_sim.maps.tiles import CellValues
from stage_sim.sensing.casters import RayCaster
from stage_sim.sensing.robot_layer import RobotLayer


@dataclass(frozen=True)
class HeightGroup:
    """The rays cast at one height, with the static layer and the robots visible there."""

    rays: np.ndarray
    owner: np.ndarray  #: per ray of the group: its robot, ranger, angle in the robot frame and range
    ranger: np.ndarray
    angle: np.ndarray
    max_range: np.ndarray
    caster: RayCaster
    robots: RobotLayer
    intensity: CellValues
    robot_visible: np.ndarray
    robot_return: np.ndarray


@dataclass(frozen=True)
class SingleCast:
    """Every ray of a world at one height, as a fused step casts them in one call
    (:meth:`~stage_sim.sim.rangers.RangerSensing.single_cast`)."""

    group: HeightGroup
    ranger_offset: np.ndarray  #: (K, 2) each ranger's origin in its robot's frame
    ranger_owner: np.ndarray  #: (K,) each ranger's robot
    trig: tuple[np.ndarray, np.ndarray, np.ndarray]  #: every beam's last angle, cos and sin (kept up to date)
    longest: float  #: the longest beam's range
    jitter: np.ndarray  #: every beam's direction noise, drawn anew before each cast (empty: no angle noise)
    noisy_rays: np.ndarray  #: the beams with a range noise ...
    noise_prop: np.ndarray  #: ... their proportional noise ...
    noise_uniform: np.ndarray  #: ... and their draws of U' ...
    noise_gauss: np.ndarray  #: ... and of G, drawn anew before each cast (``RangerSensing.draw_all_noise``)
