"""The simulation core must import and work on a machine without ROS."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]

# rclpy and every ROS message package are made unimportable before the core is imported.
_PROBE = """
import importlib, pkgutil, sys
for blocked in ("rclpy", "std_msgs", "geometry_msgs", "nav_msgs", "sensor_msgs", "tf2_msgs", "rosgraph_msgs"):
    sys.modules[blocked] = None
import stage_sim.core as core
names = [m.name for m in pkgutil.iter_modules(core.__path__, "stage_sim.core.")]
for name in names:
    importlib.import_module(name)
print(len(names))
"""


def test_every_core_module_imports_with_ros_blocked() -> None:
    result = subprocess.run([sys.executable, "-c", _PROBE], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert int(result.stdout.strip()) >= 3
