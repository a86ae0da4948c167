"""The house plan holds: the core imports without ROS, and the layer contracts of ``.importlinter`` hold."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

# rclpy and every ROS message package are made unimportable before any module outside stage_sim.ros is imported.
_PROBE = """
import importlib, pkgutil, sys
for blocked in ("rclpy", "std_msgs", "geometry_msgs", "nav_msgs", "sensor_msgs", "tf2_msgs", "rosgraph_msgs"):
    sys.modules[blocked] = None
import stage_sim
names = [m.name for m in pkgutil.walk_packages(stage_sim.__path__, "stage_sim.")
         if not m.name.startswith("stage_sim.ros") and not m.name.endswith("__main__")]
for name in names:
    importlib.import_module(name)
print(len(names))
"""


def test_every_module_outside_ros_imports_with_ros_blocked() -> None:
    result = subprocess.run([sys.executable, "-c", _PROBE], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert int(result.stdout.strip()) >= 40


def _lint_imports(config: Path) -> subprocess.CompletedProcess[str]:
    executable = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or "lint-imports"
    return subprocess.run(
        [executable, "--config", str(config), "--no-cache"], cwd=REPO, capture_output=True, text=True, timeout=300,
        env={**os.environ, "PYTHONPATH": str(REPO)},
    )


def test_layer_contracts_hold() -> None:
    result = _lint_imports(REPO / ".importlinter")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


def test_an_upward_import_breaks_the_layers(tmp_path: Path) -> None:
    """The contracts are not vacuous: the same check fails once ``sim`` imports ``rendering``."""
    scratch = tmp_path / "repo"
    shutil.copytree(REPO / "stage_sim", scratch / "stage_sim", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(REPO / ".importlinter", scratch / ".importlinter")
    kinematics = scratch / "stage_sim" / "sim" / "kinematics.py"
    kinematics.write_text(kinematics.read_text() + "\nimport stage_sim.rendering.palette  # noqa: E402, F401\n")
    result = subprocess.run(
        [shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or "lint-imports", "--no-cache"],
        cwd=scratch, capture_output=True, text=True, timeout=300, env={**os.environ, "PYTHONPATH": str(scratch)},
    )
    assert result.returncode != 0
    assert "stage_sim.sim.kinematics -> stage_sim.rendering.palette" in result.stdout


def test_no_import_cycle_between_modules_type_only_imports_included() -> None:
    import grimp

    graph = grimp.build_graph("stage_sim", cache_dir=None)
    cycles = {
        tuple(sorted((importer, imported)))
        for importer in graph.modules
        for imported in graph.find_modules_directly_imported_by(importer)
        if graph.find_shortest_chain(importer=imported, imported=importer)
    }
    assert len(graph.modules) >= 40
    assert not cycles
