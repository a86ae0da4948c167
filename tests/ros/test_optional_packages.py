"""stageros in a ROS install whose rosdep brought neither aiohttp nor the bag libraries (they come from pip)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

WITHOUT = """
import sys
from importlib.abc import MetaPathFinder

class Missing(MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {"aiohttp", "foxglove", "mcap", "mcap_ros2", "rosbags"}:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)

sys.meta_path.insert(0, Missing())
from stage_sim.ros.stageros_main import main
sys.exit(main(["stageros", *sys.argv[1:]]))
"""


def run_stageros(tmp_path: Path, *args: str) -> subprocess.CompletedProcess:
    world = tmp_path / "short.world"
    world.write_text("quit_time 1\nresolution 0.02\nposition( pose [0 0 0 0] )\n")
    return subprocess.run([sys.executable, "-c", WITHOUT, *args, "--speedup", "0", str(world)], capture_output=True,
                          text=True, timeout=60, env=dict(os.environ))


def test_without_aiohttp_stageros_runs_on_without_its_view(tmp_path: Path) -> None:
    result = run_stageros(tmp_path)
    assert result.returncode == 0, result.stderr
    assert "view: not served: the Python package 'aiohttp' is missing" in result.stderr
    assert "quit_time 1 s reached" in result.stderr + result.stdout
    assert "Traceback" not in result.stderr


def test_without_the_bag_libraries_bag_exits_2_naming_what_to_install(tmp_path: Path) -> None:
    result = run_stageros(tmp_path, "-g", "--bag", str(tmp_path / "run.mcap"))
    assert result.returncode == 2
    assert "--bag needs the Python package 'foxglove'" in result.stderr and "pip install" in result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "run.mcap").exists()
