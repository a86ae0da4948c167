"""Golden scans recorded from Stage 4.3, and stage_sim's scans at the same poses.

``tests/data/fidelity/rooms_<V>.jsonl`` (copied from the project's ``../shared/fidelity``; its README says
how each world and pose is made) holds, per line, a robot pose in ``worlds/rooms.world`` and the first
laser scan Stage computed there. Variant A is the world as it is, B has ``resolution 0.05``, C the
floorplan turned by 30°.

:func:`stage_reference_scans` replays Stage's own ray walk (``World::Raytrace``, ported line by line in
:mod:`tests.maps.stage_raytrace`) on stage_sim's static raster: it reproduces Stage's scans only if the
raster holds exactly Stage's cells, which is what the raster tests hold it to. :func:`stage_sim_scans` is
what stage_sim itself returns.
"""

from __future__ import annotations

import json
import re
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from stage_sim.maps.body_geometry import body_frame, body_shape, global_poses, transform_points
from stage_sim.maps.polygon_raster import edge_cells, vertex_cells
from stage_sim.sim.simulation import Simulation
from stage_sim.worldfile.description import Model, WorldDescription
from stage_sim.worldfile.loader import load_world_text
from tests.maps.stage_raytrace import stage_ray_ranges

REPO = Path(__file__).resolve().parents[2]


FIDELITY = REPO / "tests" / "data" / "fidelity"
WORLD = REPO / "worlds" / "rooms.world"
VARIANTS = ("A", "B", "C")
#: How each variant changes rooms.world (the fidelity README's table).
_CHANGES = {
    "A": (),
    "B": (("resolution 0.02", "resolution 0.05"),),
    "C": (("pose [ 13.525 10.825 0.000 0.000 ]", "pose [ 13.525 10.825 0.000 30.000 ]"),),
}
_ROBOT_LINE = re.compile(r'^simple_robot\( pose \[[^\]]*\] name "robot" \)$', re.MULTILINE)


@dataclass(frozen=True)
class GoldenScan:
    """One recorded scan: the robot pose (x, y, yaw in degrees) and Stage's ranges (metres)."""

    variant: str
    pose: tuple[float, float, float]
    ranges: np.ndarray


@dataclass(frozen=True)
class Figures:
    """How close one set of scans is to Stage's, as the issue measures it."""

    variant: str
    source: str
    poses: int
    beams: int
    within_1_cell: float  #: share of beams with |Stage − ours| <= 1 cell (misses on both sides count as 0)
    within_1_5_cells: float
    identical: float  #: share with |Stage − ours| < 1 mm
    hit_miss: float  #: share of beams where exactly one side reads range_max
    mean_diff_cells: float  #: mean of Stage − ours over the beams both hit, in cells
    mean_diff_cm: float

    def as_dict(self) -> dict[str, float | int | str]:
        """The figures as a JSON-ready dict (shares rounded to 1e-5, differences to 1e-4)."""
        return {k: round(v, 5) if isinstance(v, float) else v for k, v in asdict(self).items()}


def load_golden(variant: str) -> list[GoldenScan]:
    """The recorded scans of one variant, in file order."""
    path = FIDELITY / f"rooms_{variant}.jsonl"
    if not path.is_file():
        raise FileNotFoundError(
            f"golden scans not found: {path} (they are part of the repository: restore tests/data/fidelity)")
    scans = []
    with open(path, encoding="utf-8") as lines:
        for line in lines:
            row = json.loads(line)
            scans.append(GoldenScan(row["variant"], tuple(row["pose"]), np.asarray(row["stage_ranges"], dtype=float)))
    return scans


def variant_world(variant: str, pose: tuple[float, float, float]) -> WorldDescription:
    """rooms.world changed as the README says for ``variant``, with the robot at ``pose``."""
    text = WORLD.read_text(encoding="utf-8")
    for old, new in _CHANGES[variant]:
        if old not in text:
            raise ValueError(f"rooms.world no longer contains {old!r}: the fidelity variants need updating")
        text = text.replace(old, new)
    x, y, yaw = pose
    text, count = _ROBOT_LINE.subn(f'simple_robot( pose [ {x} {y} 0.000 {yaw} ] name "robot" )', text)
    if count != 1:
        raise ValueError("rooms.world no longer has the one robot line the fidelity variants replace")
    return load_world_text(text, WORLD)


def stage_sim_scans(golden: list[GoldenScan]) -> np.ndarray:
    """stage_sim's first scan at every golden pose, (poses, beams).

    One simulation per variant (its static world does not depend on the robot); the robot is put at each
    pose exactly as the world file states it (the loader's units) and the scan taken without moving."""
    first = variant_world(golden[0].variant, golden[0].pose)
    sim = Simulation(first, seed=0)
    scans = []
    for scan in golden:
        pose = _robot(variant_world(scan.variant, scan.pose)).pose
        sim.set_pose(0, pose.x, pose.y, pose.yaw)
        sim.step()
        scans.append(np.asarray(sim.scans[0][0].ranges, dtype=float))
    return np.array(scans)


def stage_reference_scans(golden: list[GoldenScan]) -> np.ndarray:
    """Stage's own ray walk on stage_sim's static raster at every golden pose, (poses, beams)."""
    sim = Simulation(variant_world(golden[0].variant, golden[0].pose), seed=0)
    static = sim.static
    ranger = sim.robots[0].rangers[0]
    layer = static.sensing_layer(ranger.ray_height)[0]
    offset = np.rint(np.array(static.origin_xy) / static.resolution).astype(np.int64)
    rows, cols = np.nonzero(layer)
    static_cells = np.stack([cols, rows], axis=1) + offset
    scans = []
    for scan in golden:
        description = variant_world(scan.variant, scan.pose)
        robot = _robot(description)
        cells = np.concatenate([static_cells, _body_cells(description, robot, static.resolution)])
        x, y, yaw = robot.pose.x, robot.pose.y, robot.pose.yaw
        c, s = np.cos(yaw), np.sin(yaw)
        ox, oy = ranger.ray_offset
        origin = (x + ox * c - oy * s, y + ox * s + oy * c)
        sensor = ranger.sensor
        scans.append(stage_ray_ranges(
            layer, offset, cells, origin, yaw + ranger.ray_yaw, sensor.fov, sensor.samples, sensor.range_max,
            static.resolution))
    return np.array(scans)


def figures(variant: str, source: str, stage: np.ndarray, ours: np.ndarray, resolution: float,
            range_max: float) -> Figures:
    """Compare scans (poses, beams) with Stage's."""
    stage, ours = np.asarray(stage, dtype=float), np.asarray(ours, dtype=float)
    diff = stage - ours
    # stage_sim's scans are float32: a miss reads range_max rounded to float32.
    stage_hit, our_hit = stage < range_max * (1 - 1e-6), ours < range_max * (1 - 1e-6)
    both = stage_hit & our_hit
    mean = float(diff[both].mean()) if both.any() else 0.0
    return Figures(
        variant=variant, source=source, poses=stage.shape[0], beams=stage.size,
        within_1_cell=float(np.mean(np.abs(diff) <= resolution * (1 + 1e-9))),
        within_1_5_cells=float(np.mean(np.abs(diff) <= 1.5 * resolution * (1 + 1e-9))),
        identical=float(np.mean(np.abs(diff) < 1e-3)),
        hit_miss=float(np.mean(stage_hit != our_hit)),
        mean_diff_cells=mean / resolution, mean_diff_cm=mean * 100,
    )


def _robot(description: WorldDescription) -> Model:
    """The model the variants place: the position model named "robot"."""
    return next(model for model in description.models if model.name == "robot")


def _body_cells(description: WorldDescription, robot: Model, resolution: float) -> np.ndarray:
    """Stage's raster cells of the robot's own blocks: they make the regions around it non-empty."""
    poses = global_poses(description)
    polygons = []
    for model in robot.walk():
        frame = body_frame(model, poses[id(model)])
        polygons += [vertex_cells(transform_points(p.points, frame), resolution) for p in body_shape(model)]
    return edge_cells(polygons)
