"""Compiled (numba) step in one call: the end poses and odometry, the contacts and every laser's cast.

Why: for one robot a step of the compiled backend made some sixty calls (kernels, numpy, Python), which
cost twice the ray walk itself. Here each part of a step is one call of the existing kernels
(:mod:`stage_sim.sim.body_kernels`, :mod:`stage_sim.sim.motion_kernels`, :mod:`stage_sim.sensing.robot_kernels`,
:mod:`stage_sim.sensing.traversal`, :mod:`stage_sim.sim.ranger_kernels`) in the order and with the arguments
the role-by-role step gives them, so every pose, flag, range and intensity is the same bit for bit
(``tests/sim/test_step_digests.py``, ``tests/sim/test_kernel_identity.py``). The role-by-role kernels take the
cosines and sines of the headings from numpy; here they are computed in the kernel (libm's, as numpy's float64
``cos`` and ``sin`` are: ``tests/sim/test_trigonometry.py`` holds them equal bit for bit), once per heading: a
step's new headings are the next one's start (remembered, and checked bit for bit before use).

What never changes between two steps of a world (bodies, static layers, beam tables, scratch arrays) travels
in one :class:`FusedWorld`: numba checks the type of every argument of every call, some 0.1 µs an array, and
a step reads some sixty arrays.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba.core import types
from numba.experimental import structref

from stage_sim.sensing import robot_kernels, traversal
from stage_sim.sim import body_kernels, motion_kernels, ranger_kernels

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}

#: What a :class:`FusedWorld` holds, in the order :func:`fused_world` takes it.
FIELDS = (
    # bodies and contacts: polygons, radii, (col0, row0, height, width, static width), cells per metre
    "vertices", "poly_start", "robot_poly", "radius", "grid", "ppm", "collides", "colliding", "can_clash",
    # the static cells of the one height band: slots, tiles, bits, place
    "slots", "tile_of_slot", "bits", "static_place",
    # the rangers and the robot layer: tables (regions, ids, row and column masks, used lines, owner), its room,
    # the regions it marked and their count, whether it holds a cell (the layer's arrays, updated in place)
    "ranger_offset", "ranger_owner", "robots_seen", "visible", "regions", "ids", "rows", "cols", "rows_used",
    "cols_used", "tile_owner", "capacity", "region_place", "width", "marked_value", "several", "marked",
    "marked_count", "active",
    # the walk: the static layer's masks, tiles, slots and used lines, place, stop map and margin
    "walk_rows", "walk_cols", "walk_tiles", "walk_slots", "walk_rows_used", "walk_cols_used", "walk_place", "stops",
    "pad", "walk_ppm",
    # the rays: ranger, angle, range, robot, slot, last angle, cos and sin
    "ranger", "angle", "rmax", "owner", "rays", "last_angle", "last_cos", "last_sin",
    # noise, drawn before each cast: direction (empty: none); rays with a range noise, their p, U' and G
    "jitter", "noisy_rays", "noise_prop", "noise_uniform", "noise_gauss",
    # intensities: static cells and values, robots' returns, the return of a cell two robots share
    "static_cells", "static_values", "robot_return", "several_return",
    # scratch: ranges, hit cells and robots; new headings, the remembered ones and their cos and sin
    "ranges", "cell", "hit_robot", "headings", "known", "known_trig",
    # the last cast through each layer, kept (see _cast_kept): the poses it was cast from and the layer's poses
    # it saw; its ranges before the noise and its intensities; per layer whether one is kept and the tiles it
    # needed; how often one was replayed
    "cast_keys", "cast_ranges", "cast_intensity", "cast_state", "replays",
    # the body velocities from the commands: each stepped drive's robots, wheelbases, velocity bounds
    "drive_rows", "wheelbases", "bounds",
)


@structref.register
class FusedWorldType(types.StructRef):
    """numba's type of a :class:`FusedWorld`."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class FusedWorld(structref.StructRefProxy):
    """What a fused step of one world reads besides the robots' state (:data:`FIELDS`), as one argument."""


structref.define_proxy(FusedWorld, FusedWorldType, list(FIELDS))


@numba.njit(**_JIT)
def fused_world(vertices, poly_start, robot_poly, radius, grid, ppm, collides, colliding, can_clash, slots,
                tile_of_slot, bits, static_place, ranger_offset, ranger_owner, robots_seen, visible, regions, ids, rows,
                cols, rows_used, cols_used, tile_owner, capacity, region_place, width, marked_value, several, marked,
                marked_count, active, walk_rows, walk_cols, walk_tiles, walk_slots, walk_rows_used, walk_cols_used,
                walk_place, stops, pad, walk_ppm, ranger, angle, rmax, owner, rays, last_angle, last_cos, last_sin,
                jitter, noisy_rays, noise_prop, noise_uniform, noise_gauss, static_cells, static_values, robot_return,
                several_return, ranges, cell, hit_robot, headings, known, known_trig, cast_keys, cast_ranges,
                cast_intensity, cast_state, replays, drive_rows, wheelbases, bounds):
    """A :class:`FusedWorld` of the :data:`FIELDS` (compiled and cached: the proxy's own constructor is not)."""
    return FusedWorld(vertices, poly_start, robot_poly, radius, grid, ppm, collides, colliding, can_clash, slots,
                      tile_of_slot, bits, static_place, ranger_offset, ranger_owner, robots_seen, visible, regions, ids,
                      rows, cols, rows_used, cols_used, tile_owner, capacity, region_place, width, marked_value,
                      several, marked, marked_count, active, walk_rows, walk_cols, walk_tiles, walk_slots,
                      walk_rows_used, walk_cols_used, walk_place, stops, pad, walk_ppm, ranger, angle, rmax, owner,
                      rays, last_angle, last_cos, last_sin, jitter, noisy_rays, noise_prop, noise_uniform, noise_gauss,
                      static_cells, static_values, robot_return, several_return, ranges, cell, hit_robot, headings,
                      known, known_trig, cast_keys, cast_ranges, cast_intensity, cast_state, replays, drive_rows,
                      wheelbases, bounds)


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
def _raster(world, robots, poses, cos, sin):
    """:func:`~stage_sim.sim.body_kernels.body_raster` of ``robots`` at ``poses`` facing (``cos``, ``sin``)."""
    grid = world.grid
    return body_kernels.body_raster(world.vertices, world.poly_start, world.robot_poly, robots,
                                    np.ascontiguousarray(poses[:, 0]), np.ascontiguousarray(poses[:, 1]), cos, sin,
                                    world.ppm, grid[0], grid[1], grid[2], grid[3])


@numba.njit(inline="always", **_JIT)
def _same(a, b):
    """Whether two floats have the same bits (NaN aside, which matches nothing): a cached heading's."""
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


@numba.njit(**_JIT)
def advance(poses, layers, layer, estimates, velocities, errors, dt, uses_odom, known, known_trig, check, integrated,
            odometry, headings):
    """The end poses of every robot (:func:`~stage_sim.sim.motion_kernels.integrate_poses`) into ``integrated``
    and the odometry of the robots that ``uses_odom`` (:func:`~stage_sim.sim.motion_kernels.integrate_estimates`)
    into ``odometry``, with the cos and sin of their start headings remembered from the last step; their new
    headings into ``headings[:, 2]`` (end poses, then odometry), whose cos and sin the step needs next.

    ``known`` (4, N): the headings whose cos and sin ``known_trig`` (4, 2, N) holds, of the poses, the
    odometry and layers 0 and 1 (a :class:`FusedWorld`'s, given apart: fewer arguments to check than the world).
    With ``check``, returns False (and does nothing) unless they are the headings of ``poses``, ``estimates``
    and ``layers[layer]`` bit for bit (a reset or a pose set between steps)."""
    n = poses.shape[0]
    if check:
        for i in range(n):
            if not (_same(poses[i, 2], known[0, i]) and _same(estimates[i, 2], known[1, i])
                    and _same(layers[layer, i, 2], known[2 + layer, i])):
                return False
    motion_kernels.integrate_poses(poses, velocities, dt, known_trig[0, 0], known_trig[0, 1], integrated)
    motion_kernels.integrate_estimates(estimates, velocities, errors, dt, known_trig[1, 0], known_trig[1, 1],
                                       uses_odom, estimates, odometry)
    for i in range(n):
        headings[i, 2] = integrated[i, 2]
        headings[n + i, 2] = odometry[i, 2]
    return True


@numba.njit(**_JIT)
def _remember(known, known_trig, row, poses):
    """Row ``row`` of ``known`` and ``known_trig``: the headings of ``poses`` and their cos and sin."""
    for i in range(poses.shape[0]):
        known[row, i] = poses[i, 2]
        known_trig[row, 0, i], known_trig[row, 1, i] = math.cos(poses[i, 2]), math.sin(poses[i, 2])


@numba.njit(**_JIT)
def whole_step(world, poses, layers, layer, estimates, velocities, errors, dt, uses_odom, stalled, cast, integrated,
               end_trig, final_trig, odometry, final, stalled_out, published, intensity):
    """A whole step: :func:`advance` from the start headings' remembered cos and sin (worked out anew when they
    are not those of ``poses``, ``estimates`` and ``layers[layer]``: the first step, a reset, a pose set between
    steps), the cos and sin of the new headings into ``end_trig`` (2, 2N), then :func:`step`, whose answer it
    returns. ``integrated``, ``end_trig`` and ``final_trig`` are the caller's scratch."""
    known, known_trig, headings = world.known, world.known_trig, world.headings
    if not advance(poses, layers, layer, estimates, velocities, errors, dt, uses_odom, known, known_trig, True,
                   integrated, odometry, headings):
        _remember(known, known_trig, 0, poses)
        _remember(known, known_trig, 1, estimates)
        _remember(known, known_trig, 2 + layer, layers[layer])
        advance(poses, layers, layer, estimates, velocities, errors, dt, uses_odom, known, known_trig, False,
                integrated, odometry, headings)
    for k in range(headings.shape[0]):
        end_trig[0, k], end_trig[1, k] = math.cos(headings[k, 2]), math.sin(headings[k, 2])
    return step(world, poses, integrated, layers, layer, velocities, stalled, odometry, uses_odom, end_trig, final,
                stalled_out, final_trig, cast, published, intensity)


@numba.njit(**_JIT)
def commanded_step(world, commands, velocities, poses, layers, layer, estimates, errors, dt, uses_odom, stalled, cast,
                   integrated, end_trig, final_trig, odometry, final, stalled_out, published, intensity):
    """A whole step from the robots' ``commands``: their body velocities into ``velocities``
    (:func:`~stage_sim.sim.motion_kernels.drive_velocities`), then :func:`whole_step` with them, whose answer it
    returns. What :meth:`~stage_sim.sim.compiled.FusedStep.step` calls, or a kernel that wraps it (an RL task's,
    which writes the commands first and reads the new state after: ``stage_sim.envs.step_kernels``)."""
    motion_kernels.drive_velocities(commands, world.drive_rows, world.wheelbases, world.bounds, velocities)
    return whole_step(world, poses, layers, layer, estimates, velocities, errors, dt, uses_odom, stalled, cast,
                      integrated, end_trig, final_trig, odometry, final, stalled_out, published, intensity)


@numba.njit(inline="always", **_JIT)
def _slot_step(worlds, s, poses, layers, parity, estimates, velocities, errors, dt, uses_odom, stalled, integrated,
               end_trig, final_trig, odometry, final, stalled_out, published, intensity, tiles):
    """:func:`whole_step` of world slot ``s`` of :func:`whole_steps`' arguments."""
    world = worlds[s]
    needed = whole_step(world, poses[s], layers[s], parity[s], estimates[s], velocities[s], errors[s], dt,
                        uses_odom[s], stalled[s], True, integrated[s], end_trig[s], final_trig[s], odometry[s],
                        final[s], stalled_out[s], published[s], intensity[s])
    tiles[s] = needed if needed > world.capacity else 0


@numba.njit(**_JIT)
def whole_steps(worlds, slots, poses, layers, parity, estimates, velocities, errors, dt, uses_odom, stalled,
                integrated, end_trig, final_trig, odometry, final, stalled_out, published, intensity, tiles):
    """:func:`whole_step` of several worlds, every ray cast, in one call: for each slot ``s`` of ``slots``, world
    ``worlds[s]`` (a typed list of :class:`FusedWorld`) with row ``s`` of every other argument (the worlds'
    state, scratch and outputs stacked, world s in its layer ``parity[s]``); into ``tiles[s]`` the tiles it
    needs when its robot layer has room for fewer (nothing cast: the caller grows the layer and casts again,
    :func:`sense_again`), else 0. For a vector env's worlds: one call instead of a call and its argument checks
    per world."""
    for k in range(slots.size):
        _slot_step(worlds, slots[k], poses, layers, parity, estimates, velocities, errors, dt, uses_odom, stalled,
                   integrated, end_trig, final_trig, odometry, final, stalled_out, published, intensity, tiles)


@numba.njit(parallel=True, **_JIT)
def whole_steps_parallel(worlds, slots, poses, layers, parity, estimates, velocities, errors, dt, uses_odom,
                         stalled, integrated, end_trig, final_trig, odometry, final, stalled_out, published,
                         intensity, tiles):
    """:func:`whole_steps` with the worlds shared among threads: each world's step reads and writes only its
    own world and rows, so the answers are the same."""
    for k in numba.prange(slots.size):
        _slot_step(worlds, slots[k], poses, layers, parity, estimates, velocities, errors, dt, uses_odom, stalled,
                   integrated, end_trig, final_trig, odometry, final, stalled_out, published, intensity, tiles)


@numba.njit(**_JIT)
def step(world, poses, integrated, layers, layer, velocities, stalled, odometry, uses_odom, end_trig, final,
         stalled_out, final_trig, cast, published, intensity):
    """The rest of a step after :func:`advance`: Stage's moves in layer ``layer`` of ``layers`` (2, N, 3), as
    :meth:`~stage_sim.sim.collision.CollisionChecker.resolve` and the simulation's step make them, then every
    ray (:func:`sense`) from the new poses, through the robots where the layer now holds them, when ``cast``.

    The robots with a velocity go to their end poses (``integrated``, whose headings' cos and sin are
    ``end_trig`` (2, 2N)) unless a cell of theirs there is a static cell of their height band or, when
    ``world.can_clash``, one of another obstacle robot as the layer holds it when they move (one by one, in
    robot order). Writes the new poses, stall flags and their cos and sin into ``final``, ``stalled_out`` and
    ``final_trig``, the layer's new poses into ``layers[layer]``, the true pose as odometry of the robots
    without ``uses_odom``, and what ``world.known`` and ``world.known_trig`` hold for the next step
    (:func:`advance`). Returns :func:`sense`'s answer (without a cast: 0). Not the raster the rays saw: each
    array a call returns costs its caller some 0.7 µs to receive, and only the rare cast into a grown layer
    needs it again (:func:`sense_again` makes it anew)."""
    n = poses.shape[0]
    known, known_trig, collides = world.known, world.known_trig, world.collides  # locals: each read of a field
    layer_poses = layers[layer].copy()  # counts a reference
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
    start_cos, start_sin = known_trig[0, 0].copy(), known_trig[0, 1].copy()
    end_cos, end_sin = end_trig[0, :n].copy(), end_trig[1, :n].copy()
    row = 2 + layer
    end_cells, end_robot = np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
    if count:
        end_cells, end_robot = _raster(world, testers, candidates, end_cos, end_sin)
        static_hit = np.zeros(n, dtype=np.bool_)
        body_kernels.static_hits(end_cells, end_robot, np.zeros(n, dtype=np.int64), 0, world.slots,
                                 world.tile_of_slot, world.bits, world.static_place, world.grid[4], static_hit)
        if world.can_clash:
            before = _raster(world, world.colliding, layer_poses, known_trig[row, 0], known_trig[row, 1])
            back = _raster(world, testers, poses, start_cos, start_sin)
            box = np.empty((3, n, 4), dtype=np.int64)
            box[0] = _boxes(layer_poses, world.radius, world.ppm)
            box[1] = _boxes(candidates, world.radius, world.ppm)
            box[2] = _boxes(poses, world.radius, world.ppm)
            body_kernels.move_one_by_one(testers, static_hit, end_cells, end_robot, before[0], before[1], back[0],
                                         back[1], world.colliding, box, refused)
        else:
            for k in range(count):
                refused[testers[k]] = static_hit[testers[k]]
    for i in range(n):
        accepted = moving[i] and not refused[i]
        for axis in range(3):
            final[i, axis] = candidates[i, axis] if accepted else poses[i, axis]
        final_trig[0, i] = end_cos[i] if accepted else start_cos[i]
        final_trig[1, i] = end_sin[i] if accepted else start_sin[i]
        stalled_out[i] = refused[i] if moving[i] else stalled[i]
        if moving[i]:
            for axis in range(3):
                layers[layer, i, axis] = final[i, axis]
            known[row, i] = final[i, 2]
            known_trig[row, 0, i], known_trig[row, 1, i] = final_trig[0, i], final_trig[1, i]
        known[0, i] = final[i, 2]
        known_trig[0, 0, i], known_trig[0, 1, i] = final_trig[0, i], final_trig[1, i]
        if uses_odom[i]:
            known_trig[1, 0, i], known_trig[1, 1, i] = end_trig[0, n + i], end_trig[1, n + i]
        else:  # gps: the odometry is the true pose
            for axis in range(3):
                odometry[i, axis] = final[i, axis]
            known_trig[1, 0, i], known_trig[1, 1, i] = final_trig[0, i], final_trig[1, i]
        known[1, i] = odometry[i, 2]
    if not cast:
        return 0
    if _cast_kept(world, layer, final, layers[layer]):
        return _replay(world, layer, published, intensity)
    if count == n and not refused.any():  # every robot where it was tested: the rays see the raster it was tested in
        cells, cell_robot = end_cells, end_robot
    else:
        cells, cell_robot = _raster(world, np.arange(n), layers[layer], known_trig[row, 0], known_trig[row, 1])
    needed = sense(world, final, final_trig, cells, cell_robot, published, intensity, layer)
    _keep_cast(world, layer, final, layers[layer], needed)
    return needed


@numba.njit(**_JIT)
def sense_again(world, layers, layer, poses, trig, published, intensity):
    """:func:`sense` again after :func:`step` found the robot layer too small (the caller grew it): through the
    raster of every robot where layer ``layer`` of ``layers`` now holds them, which is the raster :func:`step`
    cast through (the same cells in the same order: when every robot moved as tested, its end raster is this
    one)."""
    row = 2 + layer
    known_trig = world.known_trig
    cells, cell_robot = _raster(world, np.arange(poses.shape[0]), layers[layer], known_trig[row, 0],
                                known_trig[row, 1])
    needed = sense(world, poses, trig, cells, cell_robot, published, intensity, layer)
    _keep_cast(world, layer, poses, layers[layer], needed)
    return needed


@numba.njit(**_JIT)
def _cast_kept(world, layer, poses, raster):
    """Whether the cast kept for layer ``layer`` (:func:`_keep_cast`) is this one's: the robots are where it was
    cast from and where the layer had them then, bit for bit. A walk's answer depends on nothing else that can
    change (the static world, the beams and their ranges are the world's for good; a direction noise, which
    would change it, keeps nothing), so a world whose robots stand still (parked, or stalled against a wall)
    does not walk its rays again, where Stage walks them every update. One kept per layer: a robot that
    stopped stays a step behind in the layer it did not move in last, and the steps alternate the layers."""
    if not world.cast_state[layer, 0]:
        return False
    keys = world.cast_keys[layer]
    for i in range(poses.shape[0]):
        for axis in range(3):
            if not (_same(poses[i, axis], keys[0, i, axis]) and _same(raster[i, axis], keys[1, i, axis])):
                return False
    return True


@numba.njit(**_JIT)
def _keep_cast(world, layer, poses, raster, needed):
    """Keep the walk just made from ``poses`` through layer ``layer`` holding the robots at ``raster`` (its
    ranges before the noise and intensities, which :func:`sense` left in the layer's row), unless it was not made
    (``needed`` more tiles than the layer has) or its rays have a direction noise (drawn anew for every cast)."""
    if needed > world.capacity or world.jitter.size:
        return
    world.cast_keys[layer, 0] = poses
    world.cast_keys[layer, 1] = raster
    world.cast_state[layer, 0], world.cast_state[layer, 1] = 1, needed


@numba.njit(**_JIT)
def _replay(world, layer, published, intensity):
    """The cast kept for layer ``layer``, with this cast's range noise: what :func:`sense` would give (it walks the
    same rays through the same cells); the tiles it needed."""
    world.ranges[:] = world.cast_ranges[layer]
    intensity[:] = world.cast_intensity[layer]
    _publish(world, published)
    world.replays[0] += 1
    return world.cast_state[layer, 1]


@numba.njit(**_JIT)
def sense(world, poses, trig, cells, cell_robot, published, intensity, keep):
    """Every ray of one height cast from ``poses`` (their cos and sin ``trig``, (2, N)) as
    :meth:`~stage_sim.sim.rangers.RangerSensing.sense` casts them when all rangers are due: the rangers'
    origins, the robot layer from the robots' raster (``cells``, ``cell_robot``; the layer's marked regions and
    whether it holds a cell are updated in its arrays), the walk (with the direction noise drawn), the
    intensities, the range noise drawn (r + r·p·U' + G for a hit), the float32 ranges.

    With ``world.robots_seen`` (more than one robot) the robots' cells are numbered and written into the
    layer's tiles, else their regions are only marked. Returns the tiles needed; when the layer has room for
    fewer (``world.capacity``) nothing is cast: the caller grows it and calls again. Unless the rays have a
    direction noise, leaves the ranges before the noise and the intensities in row ``keep`` (the layer cast
    through) of ``cast_ranges`` and ``cast_intensity``, that row no longer kept: the caller keeps it, with where
    the robots were (:func:`_keep_cast`)."""
    w = world
    origins = np.empty((w.ranger_offset.shape[0], 2))
    motion_kernels.place_points(w.ranger_offset, w.ranger_owner, poses, trig[0], trig[1], origins)
    active = w.active
    if w.robots_seen:
        tile, local, count = robot_kernels.number_robot_regions(
            w.regions, w.marked, w.marked_count, cells, cell_robot, w.visible, w.region_place, w.width,
            w.marked_value)
        if count > w.capacity:
            return count
        active[0] = robot_kernels.write_robot_tiles(w.ids, w.rows, w.cols, w.rows_used, w.cols_used, w.tile_owner,
                                                    tile, local, cell_robot.astype(np.int32), count, w.several)
    else:  # a lone robot never sees itself, but its cells make Stage's regions around it non-empty
        robot_kernels.number_robot_regions(
            w.regions, w.marked, w.marked_count, cells, np.zeros(cells.size, dtype=np.int64),
            np.zeros(1, dtype=np.bool_), w.region_place, w.width, w.marked_value)
        count = 0
    ranger_owner, ranges = w.ranger_owner, w.ranges  # locals: each read of a field counts a reference
    heading = np.empty(ranger_owner.size)
    for k in range(ranger_owner.size):
        heading[k] = poses[ranger_owner[k], 2]
    traversal.cast_serial(
        (w.walk_rows, w.walk_cols, w.walk_tiles, w.walk_slots, w.walk_rows_used, w.walk_cols_used),
        (w.regions, w.ids, w.rows, w.cols, w.rows_used, w.cols_used, w.tile_owner), (True, active[0]),
        w.walk_place, w.stops, w.pad, w.marked[:w.marked_count[0]], origins, w.ranger, heading, w.angle, w.jitter,
        (w.last_angle, w.last_cos, w.last_sin), w.rmax, w.walk_ppm, w.owner, w.rays, ranges, w.cell, w.hit_robot)
    ranger_kernels.hit_intensity(w.cell, w.hit_robot, w.static_cells, w.static_values, w.robot_return, w.robots_seen,
                                 w.several, w.several_return, w.rays, intensity)
    if not w.jitter.size:
        w.cast_state[keep, 0] = 0
        w.cast_ranges[keep] = ranges
        w.cast_intensity[keep] = intensity
    _publish(w, published)
    return count


@numba.njit(**_JIT)
def _publish(w, published):
    """The range noise drawn for this cast on the walk's ranges (r + r·p·U' + G for a hit), as float32 into
    ``published``."""
    ranges = w.ranges
    noisy_rays, rmax, prop, uniform, gauss = w.noisy_rays, w.rmax, w.noise_prop, w.noise_uniform, w.noise_gauss
    for k in range(noisy_rays.size):
        i = noisy_rays[k]
        if ranges[i] < rmax[i]:
            ranges[i] = ranges[i] + ranges[i] * prop[k] * uniform[k] + gauss[k]
    for i in range(ranges.size):
        published[i] = np.float32(ranges[i])
