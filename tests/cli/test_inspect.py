"""``stage_sim inspect``: what a world contains, as text or JSON; exit 2 with a located message on errors."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from stage_sim import cli
from tests.worldfile.test_loader import write_rooms, write_willow

REPO = Path(__file__).resolve().parents[2]


def run_json(world: Path, capsys: pytest.CaptureFixture[str]) -> dict:
    assert cli.main(["inspect", str(world), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


NESTED_LASER = """position(
  name "bot"
  ranger( sensor( samples 3 ) )
  model(
    name "mast"
    ranger( name "high" sensor( samples 5 ) )
  )
)
ranger( name "alone" sensor( samples 7 ) )
"""


def test_a_sensor_the_simulation_ignores_has_no_robot_and_a_located_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    world = tmp_path / "nested.world"
    world.write_text(NESTED_LASER)
    data = run_json(world, capsys)
    assert {r["name"]: r["robot"] for r in data["rangers"]} == {"bot.ranger:0": "bot", "high": None, "alone": None}
    located = {(w["line"], w["column"]): w["message"] for w in data["warnings"] if "is not simulated" in w["message"]}
    assert located.keys() == {(6, 5), (9, 1)}
    assert located[(6, 5)].startswith("ranger 'high' is not simulated: it sits on model 'mast'")
    assert "only the direct children of a position model" in located[(6, 5)]
    assert located[(9, 1)].startswith("ranger 'alone' is not simulated: it sits at the top level")
    assert cli.main(["inspect", str(world)]) == 0
    assert f"{world}:6:5: ranger 'high' is not simulated" in capsys.readouterr().out


def test_json_report_of_rooms(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = run_json(write_rooms(tmp_path), capsys)
    world = data["world"]
    assert world["name"] == "rooms.world" and world["resolution"] == 0.02 and world["interval_sim"] == 0.1
    assert world["window"]["scale"] == 25
    (robot,) = data["robots"]
    assert robot["index"] == 0 and robot["name"] == "robot" and robot["drive"] == "diff"
    assert robot["pose"] == {"x": 11.1, "y": 9.2, "z": 0.0, "yaw": pytest.approx(math.pi / 2)}
    assert robot["size"] == [0.4, 0.3, 0.2] and robot["localization"] == "odom"
    assert robot["odom_error"] == [0.03, 0.03, 0.0, pytest.approx(0.05 * math.pi / 180)]
    (ranger,) = data["rangers"]
    assert ranger["name"] == "robot.ranger:0" and ranger["robot"] == "robot"
    # global pose: robot at yaw 90°, laser 0.23 m ahead, stacked on the 0.2 m tall body, z -0.15
    assert ranger["pose"]["x"] == pytest.approx(11.1) and ranger["pose"]["y"] == pytest.approx(9.43)
    assert ranger["pose"]["z"] == pytest.approx(0.05)
    (sensor,) = ranger["sensors"]
    assert sensor["samples"] == 240 and sensor["fov"] == pytest.approx(240 * math.pi / 180)
    assert (sensor["range_min"], sensor["range_max"]) == (0.0, 5.6)
    assert data["models"] == 3 and data["warnings"] == []
    assert data["static"]["models"] > 0 and data["static"]["polygons"] >= data["static"]["models"]
    assert len(data["static"]["extent"]) == 4


def test_json_report_lists_warnings_with_locations(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_willow(tmp_path)
    data = run_json(path, capsys)
    assert [r["name"] for r in data["robots"]] == ["pr2"] and data["robots"][0]["drive"] == "omni"
    assert data["robots"][0]["odom_error"] is None
    assert data["rangers"][0]["sensors"][0]["range_max"] == 5.0
    (warning,) = data["warnings"]
    assert (warning["file"], warning["line"], warning["column"]) == (str(path), 10, 5)
    assert "range_max" in warning["message"]


def test_text_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_willow(tmp_path)
    assert cli.main(["inspect", str(path)]) == 0
    out = capsys.readouterr().out
    assert "world willow-pr2.world" in out and "resolution 0.02 m" in out
    assert "[0] pr2  drive omni" in out and "odom_error none" in out
    assert "pr2.ranger:0 on pr2" in out and "samples 1081" in out and "fov 4.71675 rad" in out
    assert "range [0 5] m" in out
    assert f"warnings: 1\n  {path}:10:5: Stage 3 key 'range_max' ignored" in out


def test_world_error_exits_2_with_location_on_stderr(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    world = tmp_path / "bad.world"
    world.write_text("model(\n  size [1]\n)\n")
    assert cli.main(["inspect", str(world)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith(f"{world}:2:3: 'size' has too few values (found 1 values, expected 3 values)")


def test_unknown_world_name_exits_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["inspect", "no-such-world-anywhere"]) == 2
    assert "no-such-world-anywhere" in capsys.readouterr().err


def test_bundled_world_names_are_resolved(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from stage_sim.worldfile.bundled import data_root

    monkeypatch.chdir(tmp_path)
    assert cli.main(["inspect", "rooms", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["world"]["path"] == str(data_root() / "worlds" / "rooms.world")


def test_a_subcommand_is_required(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        cli.main([])
    assert info.value.code == 2


def test_console_entry_has_no_traceback(tmp_path: Path) -> None:
    world = tmp_path / "bad.world"
    world.write_text("resolution 1e-3\n")
    result = subprocess.run(
        [sys.executable, "-c", "import sys; from stage_sim.cli import main; sys.exit(main(sys.argv[1:]))",
         "inspect", str(world)],
        cwd=REPO, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert result.returncode == 2
    assert "Traceback" not in result.stderr and f"{world}:1:12:" in result.stderr
