"""Compiled (numba) intensities of a cast: what :meth:`RangerSensing._cast` computes with numpy, in one pass.

A beam's intensity is the ``ranger_return`` of what it hit: the static model of the cell (a
:class:`~stage_sim.maps.tiles.CellValues` lookup), the robot hit, or for a cell two robots share the
brighter of all robots' returns; 0 on a miss.
"""

from __future__ import annotations

import numba
import numpy as np

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}
#: Rays per work item of the parallel loop.
_CHUNK = 4096


@numba.njit(inline="always", **_JIT)
def _hit_intensity(cell, hit_robot, static_cells, static_values, robot_return, robots_seen, several, several_return,
                   rays, out, a, b):
    uniform = static_cells.size == 0
    base = static_values[0] if static_values.size else np.float32(0.0)
    for i in range(a, b):
        value = np.float32(0.0)
        if cell[i] >= 0:
            robot = hit_robot[i]
            if robot == -1:
                value = base if uniform else static_values[np.searchsorted(static_cells, cell[i])]
            elif robots_seen:
                value = robot_return[robot] if robot >= 0 else (np.float32(several_return) if robot == several
                                                                else np.float32(0.0))
        out[rays[i]] = value


@numba.njit(**_JIT)
def hit_intensity(cell, hit_robot, static_cells, static_values, robot_return, robots_seen, several, several_return,
                  rays, out):
    """``out[rays[i]]``: the intensity of ray i, from its hit cell (-1: a miss) and robot (-1: none,
    ``several``: two or more). ``static_cells``, ``static_values``: the static returns (no cells: every cell
    holds ``static_values[0]``); ``robots_seen``: whether robots may be hit at all (more than one robot)."""
    _hit_intensity(cell, hit_robot, static_cells, static_values, robot_return, robots_seen, several, several_return,
                   rays, out, 0, cell.size)


@numba.njit(parallel=True, **_JIT)
def hit_intensity_parallel(cell, hit_robot, static_cells, static_values, robot_return, robots_seen, several,
                           several_return, rays, out):
    """:func:`hit_intensity`, chunks of rays on numba's threads."""
    n = cell.size
    for k in numba.prange((n + _CHUNK - 1) // _CHUNK):
        _hit_intensity(cell, hit_robot, static_cells, static_values, robot_return, robots_seen, several,
                       several_return, rays, out, k * _CHUNK, min(n, (k + 1) * _CHUNK))
