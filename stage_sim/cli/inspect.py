"""``stage_sim inspect WORLD [--json]``: what the simulator will make of a world, without simulating it.

Settings, robots in stageros order, rangers, the static obstacles and every warning.
"""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

from stage_sim.maps.body_geometry import global_poses
from stage_sim.maps.raster import static_outline_summary
from stage_sim.worldfile.description import Pose, WorldDescription
from stage_sim.worldfile.loader import load_world
from stage_sim.worldfile.sensor_kinds import robot_sensors


def inspect_data(description: WorldDescription) -> dict[str, Any]:
    """Everything ``inspect`` reports, as JSON-ready data."""
    settings = description.settings
    world: dict[str, Any] = {
        "path": str(description.path),
        "name": settings.name,
        "resolution": settings.resolution,
        "interval_sim": settings.interval_sim,
        "quit_time": settings.quit_time,
        "speedup": settings.speedup,
        "threads": settings.threads,
        "unit_length": settings.unit_length,
        "unit_angle": settings.unit_angle,
        "window": None,
    }
    if settings.window is not None:
        window = settings.window
        world["window"] = {
            "size": list(window.size),
            "center": list(window.center),
            "rotate": list(window.rotate),
            "scale": window.scale,
        }
    robots, rangers = [], []
    robot_of: dict[int, str] = {}  # the robot each sensor belongs to, by the simulation's rule
    poses = global_poses(description)
    for model in description.walk():
        pose = poses[id(model)]
        pose = Pose(pose.x, pose.y, pose.z, _wrap(pose.yaw))
        if model.type == "position" and model.position is not None:
            pos = model.position
            robots.append(
                {
                    "index": len(robots),
                    "name": model.name,
                    "drive": pos.drive,
                    "pose": _pose(pose),
                    "size": list(model.size),
                    "localization": pos.localization,
                    "localization_origin": _pose(pos.localization_origin) if pos.localization_origin else None,
                    "odom_error": list(pos.odom_error) if pos.odom_error is not None else None,
                    "velocity_bounds": list(pos.velocity_bounds),
                    "wheelbase": pos.wheelbase,
                }
            )
            robot_of.update((id(sensor), model.name) for sensor in robot_sensors(model))
        if model.type == "ranger":
            rangers.append(
                {
                    "name": model.name,
                    "robot": robot_of.get(id(model)),
                    "pose": _pose(pose),
                    "sensors": [
                        {
                            "samples": s.samples,
                            "fov": s.fov,
                            "range_min": s.range_min,
                            "range_max": s.range_max,
                            "pose": _pose(s.pose),
                            "noise": list(s.noise),
                        }
                        for s in model.sensors
                    ],
                }
            )
    data: dict[str, Any] = {
        "world": world,
        "robots": robots,
        "rangers": rangers,
        "models": sum(1 for _ in description.walk()),
    }
    data["static"] = static_summary(description)
    data["warnings"] = [
        {
            "message": w.message,
            "file": w.location.file if w.location else None,
            "line": w.location.line if w.location else None,
            "column": w.location.column if w.location else None,
        }
        for w in description.warnings
    ]
    return data


def static_summary(description: WorldDescription) -> dict[str, Any]:
    """Static models, polygons and their extent, from the outlines alone: inspect never rasterises."""
    return static_outline_summary(description)


def format_inspect(data: dict[str, Any]) -> str:
    """The human-readable ``inspect`` report."""
    world = data["world"]
    angle = "degrees" if math.isclose(world["unit_angle"], math.pi / 180) else "radians"
    lines = [
        f"world {world['name']} ({world['path']})",
        f"  resolution {world['resolution']:g} m  interval_sim {world['interval_sim']:g} s  "
        f"quit_time {world['quit_time']:g} s  speedup {world['speedup']:g}  threads {world['threads']}",
        f"  units: length x{world['unit_length']:g} m, angle {angle}",
    ]
    if world["window"] is not None:
        w = world["window"]
        lines.append(
            f"  window {w['size'][0]:g}x{w['size'][1]:g} px, center ({w['center'][0]:g}, "
            f"{w['center'][1]:g}) m, scale {w['scale']:g} px/m"
        )
    lines.append(f"models: {data['models']}")
    lines.append(f"robots: {len(data['robots'])}")
    for robot in data["robots"]:
        error = "none (drawn per run)" if robot["odom_error"] is None else _list(robot["odom_error"])
        lines.append(
            f"  [{robot['index']}] {robot['name']}  drive {robot['drive']}  "
            f"pose {_pose_text(robot['pose'])}  size {_list(robot['size'])} m  "
            f"localization {robot['localization']}  odom_error {error}"
        )
    lines.append(f"rangers: {len(data['rangers'])}")
    for ranger in data["rangers"]:
        owner = f" on {ranger['robot']}" if ranger["robot"] else ""
        lines.append(f"  {ranger['name']}{owner}  pose {_pose_text(ranger['pose'])}")
        for k, s in enumerate(ranger["sensors"]):
            lines.append(
                f"    sensor {k}: samples {s['samples']}  fov {s['fov']:.6g} rad  range "
                f"[{s['range_min']:g} {s['range_max']:g}] m  pose {_pose_text(s['pose'])}"
            )
    static = data["static"]
    extent = "none" if static["extent"] is None else _list(static["extent"]) + " m"
    lines.append(f"static world: {static['models']} models, {static['polygons']} polygons, extent {extent}")
    lines.append(f"warnings: {len(data['warnings'])}")
    for w in data["warnings"]:
        where = f"{w['file']}:{w['line']}:{w['column']}: " if w["file"] else ""
        lines.append(f"  {where}{w['message']}")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    data = inspect_data(load_world(args.world))
    print(json.dumps(data, indent=2) if args.json else format_inspect(data))
    return 0


def add_command(subparsers: Any) -> None:
    parser = subparsers.add_parser("inspect", help="show what a world file contains and every warning")
    parser.add_argument("world", help="world file path, or the name of a bundled world")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(run=run)


def _wrap(angle: float) -> float:
    """Angle in (-pi, pi]."""
    wrapped = math.remainder(angle, 2 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


def _pose(pose: Pose) -> dict[str, float]:
    return {"x": pose.x, "y": pose.y, "z": pose.z, "yaw": pose.yaw}


def _pose_text(pose: dict[str, float]) -> str:
    return f"({pose['x']:.6g}, {pose['y']:.6g}, {pose['z']:.6g}, yaw {pose['yaw']:.6g} rad)"


def _list(values: list[float]) -> str:
    return "[" + " ".join(f"{v:.6g}" for v in values) + "]"
