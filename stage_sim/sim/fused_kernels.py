"""Compiled (numba) step in two calls: the moves with their contacts and odometry, then every laser's cast.

Why: for one robot a step of the compiled backend made some sixty calls (kernels, numpy, Python), which
cost twice the ray walk itself. Here each half of a step is one call of the existing kernels
(:mod:`stage_sim.sim.body_kernels`, :mod:`stage_sim.sim.motion_kernels`, :mod:`stage_sim.sensing.robot_kernels`,
:mod:`stage_sim.sensing.traversal`, :mod:`stage_sim.sim.ranger_kernels`) in the order and with the arguments
the role-by-role step gives them, so every pose, flag, range and intensity is the same bit for bit
(``tests/sim/test_step_digests.py``, ``tests/sim/test_kernel_identity.py``). The trigonometry stays in numpy:
the caller passes the cosines and sines of every heading the kernels place a point with.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from stage_sim.sensing import robot_kernels, traversal
from stage_sim.sim import body_kernels, motion_kernels, ranger_kernels

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(**_JIT)
def _boxes(poses, radius, ppm):
    """:meth:`~stage_sim.sim.compiled.CompiledCollisionChecker._boxes`, the same arithmetic."""
    box = np.empty((poses.shape[0], 4), dtype=np.int64)
    for r in range(poses.shape[0]):
        for axis in range(2):
            box[r, axis] = np.int64(math.floor((poses[r, axis] - radius[r]) * ppm) - 1.0)
            box[r, 2 + axis] = np.int64(math.floor((poses[r, axis] + radius[r]) * ppm) + 1.0)
    return box


@numba.njit(**_JIT)
def _raster(bodies, robots, poses, cos, sin, grid, ppm):
    """:func:`~stage_sim.sim.body_kernels.body_raster` of ``robots`` at ``poses`` facing (``cos``, ``sin``)."""
    vertices, poly_start, robot_poly = bodies
    return body_kernels.body_raster(vertices, poly_start, robot_poly, robots, np.ascontiguousarray(poses[:, 0]),
                                    np.ascontiguousarray(poses[:, 1]), cos, sin, ppm, grid[0], grid[1], grid[2],
                                    grid[3])


@numba.njit(**_JIT)
def move(poses, integrated, layer_poses, velocities, stalled, estimates, errors, dt, uses_odom, start_trig, end_trig,
         layer_trig, odometry_trig, bodies, radius, grid, ppm, collides, colliding, can_clash, static, final,
         stalled_out, layer_out, odometry_out, final_trig):
    """One update of Stage's moves in the layer whose robots stand at ``layer_poses``, as
    :meth:`~stage_sim.sim.collision.CollisionChecker.resolve` and the simulation's step do it: the end poses
    (``integrated``, :func:`~stage_sim.sim.motion_kernels.integrate_poses` of every robot) of the robots with a
    velocity, tested against the static cells (``static``: the one height band's slots, tiles, bits and place)
    and, when ``can_clash``, one by one against the other obstacle robots; then the odometry.

    Writes the new poses, stall flags, layer poses and odometry into ``final``, ``stalled_out``, ``layer_out``
    and ``odometry_out``, the cos and sin of the new poses into ``final_trig``; returns the raster (cell, robot)
    of the layer's new poses, which the rays read. ``*_trig``: (2, N) numpy cos and sin of the headings of
    ``poses``, ``integrated``, ``layer_poses`` and ``estimates``; ``bodies``: (vertices, polygon starts, robot
    polygons); ``grid``: (col0, row0, height, width) of the raster."""
    n = poses.shape[0]
    moving = np.zeros(n, dtype=np.bool_)
    candidates = poses.copy()
    testers = np.empty(n, dtype=np.int64)
    count = 0
    for i in range(n):
        moving[i] = velocities[i, 0] != 0.0 or velocities[i, 1] != 0.0 or velocities[i, 2] != 0.0
        if moving[i]:
            candidates[i] = integrated[i]
            if collides[i]:
                testers[count] = i
                count += 1
    testers = testers[:count]
    refused = np.zeros(n, dtype=np.bool_)
    if count:
        cells, owner = _raster(bodies, testers, candidates, end_trig[0], end_trig[1], grid, ppm)
        static_hit = np.zeros(n, dtype=np.bool_)
        slots, tile_of_slot, bits, place = static
        body_kernels.static_hits(cells, owner, np.zeros(n, dtype=np.int64), 0, slots, tile_of_slot, bits, place,
                                 grid[3], static_hit)
        if can_clash:
            before = _raster(bodies, colliding, layer_poses, layer_trig[0], layer_trig[1], grid, ppm)
            back = _raster(bodies, testers, poses, start_trig[0], start_trig[1], grid, ppm)
            box = np.empty((3, n, 4), dtype=np.int64)
            box[0] = _boxes(layer_poses, radius, ppm)
            box[1] = _boxes(candidates, radius, ppm)
            box[2] = _boxes(poses, radius, ppm)
            body_kernels.move_one_by_one(testers, static_hit, cells, owner, before[0], before[1], back[0], back[1],
                                         colliding, box, refused)
        else:
            for k in range(count):
                refused[testers[k]] = static_hit[testers[k]]
    layer_cos = np.empty(n)
    layer_sin = np.empty(n)
    for i in range(n):
        source = poses if refused[i] else candidates
        trig = start_trig if refused[i] or not moving[i] else end_trig
        for axis in range(3):
            final[i, axis] = source[i, axis]
            layer_out[i, axis] = final[i, axis] if moving[i] else layer_poses[i, axis]
        final_trig[0, i], final_trig[1, i] = trig[0, i], trig[1, i]
        stalled_out[i] = refused[i] if moving[i] else stalled[i]
        layer_cos[i] = trig[0, i] if moving[i] else layer_trig[0, i]
        layer_sin[i] = trig[1, i] if moving[i] else layer_trig[1, i]
    motion_kernels.integrate_estimates(estimates, velocities, errors, dt, odometry_trig[0], odometry_trig[1],
                                       uses_odom, final, odometry_out)
    return _raster(bodies, np.arange(n), layer_out, layer_cos, layer_sin, grid, ppm)


@numba.njit(**_JIT)
def sense(poses, trig, ranger_offset, ranger_owner, cells, cell_robot, robots_seen, visible, layer, old_marked, active,
          capacity, region_place, width, marked_value, several, world, caster_place, stops, pad, ranger, angle, rmax,
          owner, rays, jitter, beam_trig, ppm, static_cells, static_values, robot_return, several_return, ranges, cell,
          hit_robot, published, intensity):
    """Every ray of one height cast from ``poses`` (their cos and sin ``trig``, (2, N)) as
    :meth:`~stage_sim.sim.rangers.RangerSensing.sense` casts them when all rangers are due and without noise:
    the rangers' origins, the robot layer (``layer``: its regions, ids, row and column masks, used lines and
    owners) from the robots' raster (``cells``, ``cell_robot``), the walk, the intensities, the float32 ranges.

    With ``robots_seen`` (more than one robot) the robots' cells are numbered and written into the layer's
    tiles, else their regions are only marked. Returns (regions marked, tiles needed, whether the layer holds
    a cell); when the layer has room for fewer tiles than needed (``capacity``) nothing is cast: the caller
    grows it and calls again."""
    origins = np.empty((ranger_offset.shape[0], 2))
    motion_kernels.place_points(ranger_offset, ranger_owner, poses, trig[0], trig[1], origins)
    regions, ids, rows, cols, rows_used, cols_used, tile_owner = layer
    if robots_seen:
        marked, tile, local, count = robot_kernels.number_robot_regions(
            regions, old_marked, cells, cell_robot, visible, region_place, width, marked_value)
        if count > capacity:
            return marked, count, active
        active = robot_kernels.write_robot_tiles(ids, rows, cols, rows_used, cols_used, tile_owner, tile, local,
                                                 cell_robot.astype(np.int32), count, several)
    else:  # a lone robot never sees itself, but its cells make Stage's regions around it non-empty
        marked = robot_kernels.number_robot_regions(
            regions, old_marked, cells, np.zeros(cells.size, dtype=np.int64), np.zeros(1, dtype=np.bool_),
            region_place, width, marked_value)[0]
        count = 0
    heading = np.empty(ranger_owner.size)
    for k in range(ranger_owner.size):
        heading[k] = poses[ranger_owner[k], 2]
    traversal.cast_serial(world, layer, (True, active), caster_place, stops, pad, marked, origins, ranger, heading,
                          angle, jitter, beam_trig, rmax, ppm, owner, rays, ranges, cell, hit_robot)
    ranger_kernels.hit_intensity(cell, hit_robot, static_cells, static_values, robot_return, robots_seen, several,
                                 several_return, rays, intensity)
    for i in range(ranges.size):
        published[i] = np.float32(ranges[i])
    return marked, count, active
