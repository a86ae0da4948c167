"""The ``stage_sim`` console script: ROS-free tools around world files.

``stage_sim inspect WORLD [--json]`` shows what the simulator will make of a world: settings, robots in
stageros order, rangers, the static obstacles and every warning. Exit status 0 on success, 2 when the
world cannot be loaded (the message, with file:line:column, goes to stderr). ``stage_sim render WORLD -o
out.png`` draws it (``-o out.gif`` records a run), with the same exit status. New subcommands register in
:data:`COMMANDS`.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from stage_sim.core.body_geometry import global_poses
from stage_sim.core.errors import WorldError
from stage_sim.core.world_description import Model, Pose, WorldDescription
from stage_sim.core.world_loader import load_world

if TYPE_CHECKING:
    from stage_sim.core.simulation import Simulation


def resolve_world(name: str) -> Path:
    """An existing file as given, else a bundled world by name (when bundled data is installed)."""
    path = Path(name)
    if path.is_file():
        return path
    try:
        from stage_sim.core.bundled import find_world
    except ImportError:
        return path
    try:
        return find_world(name)
    except FileNotFoundError as exc:
        raise WorldError(str(exc)) from exc


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
    robot_of: dict[int, str] = {}
    poses = global_poses(description)
    for model, parent in _with_parents(description):
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
            robot_of[id(model)] = model.name
        elif parent is not None and id(parent) in robot_of:
            robot_of[id(model)] = robot_of[id(parent)]
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
    static = static_summary(description)
    if static is not None:
        data["static"] = static
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


def static_summary(description: WorldDescription) -> dict[str, Any] | None:
    """Obstacle extent and occupied-cell count of the static world (None until world_raster exists)."""
    try:
        from stage_sim.core.world_raster import build_static_raster
    except ImportError:
        return None
    raster = build_static_raster(description)
    extent = raster.obstacle_extent()
    return {"occupied_cells": raster.occupied_cell_count, "extent": list(extent) if extent else None}


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
    if "static" in data:
        static = data["static"]
        extent = "none" if static["extent"] is None else _list(static["extent"]) + " m"
        lines.append(f"static world: {static['occupied_cells']} occupied cells, extent {extent}")
    lines.append(f"warnings: {len(data['warnings'])}")
    for w in data["warnings"]:
        where = f"{w['file']}:{w['line']}:{w['column']}: " if w["file"] else ""
        lines.append(f"  {where}{w['message']}")
    return "\n".join(lines)


def _inspect(args: argparse.Namespace) -> int:
    data = inspect_data(load_world(resolve_world(args.world)))
    print(json.dumps(data, indent=2) if args.json else format_inspect(data))
    return 0


def _add_inspect(subparsers: Any) -> None:
    parser = subparsers.add_parser("inspect", help="show what a world file contains and every warning")
    parser.add_argument("world", help="world file path, or the name of a bundled world")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(run=_inspect)


STRAIGHT_SPEED = 0.3
"""m/s of ``render --controller straight``: every robot drives straight ahead until something stops it."""


def _render(args: argparse.Namespace) -> int:
    from stage_sim.core.simulation import Simulation
    from stage_sim.rendering.recorder import Recorder

    world = resolve_world(args.world)
    sim = Simulation.from_world(world, seed=args.seed)
    output = args.output or Path(f"{world.stem}.png")
    try:
        recorder = Recorder(
            sim, output, every_s=args.record_every, fps=args.record_fps, trail_s=args.trail,
            scale=args.scale, lasers=not args.no_lasers, grid=args.grid,
        )
    except ValueError as exc:
        print(f"stage_sim render: {exc}", file=sys.stderr)
        return 2
    drive = _CONTROLLERS[args.controller](sim, args.seed)
    for _ in range(args.steps):
        drive()
        sim.step()
        recorder.capture_if_due()
    try:
        recorder.close()
    except OSError as exc:
        print(f"stage_sim render: cannot write {output}: {exc}", file=sys.stderr)
        return 1
    print(f"{output}: {recorder.frame_count} frame(s) up to sim time {sim.sim_time:g} s")
    return 0


def _straight(sim: Simulation, seed: int | None) -> Callable[[], None]:
    """Every robot commanded straight ahead once (commands persist; the CLI's simulation has no watchdog)."""
    for robot in range(len(sim.robots)):
        sim.set_velocity(robot, STRAIGHT_SPEED, 0.0, 0.0)
    return lambda: None


def _wander(sim: Simulation, seed: int | None) -> Callable[[], None]:
    """The ``wander`` node's reactive strategy on every robot's first laser (robots without one stay put)."""
    from stage_sim.core.wander_driver import WanderDriver

    return WanderDriver(sim, seed).decide


_CONTROLLERS: dict[str, Callable[[Simulation, int | None], Callable[[], None]]] = {
    "straight": _straight,
    "wander": _wander,
}


def _add_render(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "render", help="draw a world (optionally after some steps) to a PNG, or record the steps as a GIF",
        description="Draw the world, its robots and their lasers as Stage's window would. An output ending in "
        ".gif records a frame every --record-every sim seconds of the --steps run; .png is the final state.",
    )
    parser.add_argument("world", help="world file path, or the name of a bundled world")
    parser.add_argument("-o", "--output", type=_image_path, help="output .png or .gif (default: WORLD-NAME.png)")
    parser.add_argument("--scale", type=_positive, help="pixels per metre (default: the world's window scale)")
    parser.add_argument("--no-lasers", action="store_true", help="do not draw the laser rays")
    parser.add_argument("--grid", action="store_true", help="draw a 1 m grid")
    parser.add_argument("--seed", type=int, default=0, help="simulation (and wanderer) seed (default: 0)")
    parser.add_argument("--steps", type=_count, default=0, help="steps to simulate first (default: 0)")
    parser.add_argument(
        "--controller", choices=sorted(_CONTROLLERS), default="straight",
        help=f"who drives during --steps: 'straight' at {STRAIGHT_SPEED} m/s, or the wander node's strategy",
    )
    parser.add_argument("--trail", type=float, default=10.0, help="sim seconds of path drawn behind robots (0: none)")
    parser.add_argument("--record-every", type=_positive, default=0.5, help="sim seconds between GIF frames")
    parser.add_argument("--record-fps", type=_positive, help="GIF playback frames per second (default: real time)")
    parser.set_defaults(run=_render)


def _image_path(text: str) -> Path:
    path = Path(text)
    if path.suffix.lower() not in (".png", ".gif"):
        raise argparse.ArgumentTypeError(f"'{text}' must end in .png or .gif")
    return path


def _positive(text: str) -> float:
    value = float(text)
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be a positive number, not {text}")
    return value


def _count(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be 0 or more, not {text}")
    return value


COMMANDS: list[Callable[[Any], None]] = [_add_inspect, _add_render]
"""Each entry adds one subcommand and sets ``run``."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="stage_sim", description=__doc__.splitlines()[0])
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in COMMANDS:
        add(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Console-script entry point; returns the exit status."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.run(args))
    except WorldError as exc:
        print(exc, file=sys.stderr)
        return 2


def _with_parents(description: WorldDescription) -> Iterator[tuple[Model, Model | None]]:
    """Every model with its parent, in pre-order (the robot index order of stageros)."""

    def visit(model: Model, parent: Model | None) -> Iterator[tuple[Model, Model | None]]:
        yield model, parent
        for child in model.children:
            yield from visit(child, model)

    for top in description.models:
        yield from visit(top, None)


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


if __name__ == "__main__":
    sys.exit(main())
