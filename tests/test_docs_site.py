"""The README guides and the documentation site's generators hold: links resolve, tables come from the data.

The site itself is built in strict mode by `make docs` (CI runs it); these tests check, without building it,
what a reader would meet first: the README's links and commands, every generated table of every page against
the committed benchmark data, and the API reference covering every package in layer order.
"""

from __future__ import annotations

import importlib.util
import json
import re
import sys
from pathlib import Path
from types import ModuleType

import pytest
from mkdocs.exceptions import PluginError

REPO = Path(__file__).resolve().parents[1]
TOOLS = REPO / "tools"


def _hook(name: str) -> ModuleType:
    """A docs hook loaded as MkDocs loads it: by path, with its folder on sys.path."""
    sys.path.insert(0, str(TOOLS))
    try:
        spec = importlib.util.spec_from_file_location(name, TOOLS / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(TOOLS))
    return module


tables = _hook("docs_tables")
api = _hook("docs_api")
roles = _hook("docs_rst_roles")


def test_readme_is_short_and_has_exactly_the_two_setup_commands() -> None:
    readme = (REPO / "README.md").read_text()
    assert len(readme.splitlines()) <= 250
    commands = re.findall(r"^make (\w+)", readme.split("## The two commands")[1].split("\n## ")[0], re.MULTILINE)
    assert commands == ["run", "test"]


def test_every_relative_link_of_the_readme_and_docs_exists() -> None:
    pages = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
    for page in pages:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", page.read_text()):
            if "://" in target or target.startswith("api/"):  # api/ pages are generated at build time
                continue
            assert (page.parent / target).exists(), f"{page.name}: broken link {target}"


def test_every_table_of_the_docs_renders_from_the_committed_data() -> None:
    rendered = 0
    for page in sorted((REPO / "docs").glob("*.md")):
        markdown = page.read_text()
        out = tables.on_page_markdown(markdown, page=None, config=None, files=None)
        assert "<!-- bench" not in out, page.name
        rendered += len(tables.MARKER.findall(markdown))
        assert out.count("*Measured by `make bench") == len(tables.MARKER.findall(markdown)), page.name
    assert rendered >= 10


@pytest.fixture
def bench_data(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    (tmp_path / "machine.json").write_text(json.dumps({"cores": 2, "cpu": "Test CPU", "quick": True}))
    (tmp_path / "demo.command").write_text("python benchmarks/demo.py --fast\n")
    rows = [{"case": "a", "robots": 1, "rate": 1234.5678, "share": 0.99994}, {"case": "b", "robots": 10, "rate": 2.5}]
    (tmp_path / "demo.jsonl").write_text("".join(json.dumps(row) + "\n" for row in rows))
    monkeypatch.setattr(tables, "DATA", tmp_path)
    return tmp_path


def test_a_table_holds_the_selected_lines_and_says_which_command_made_them(bench_data: Path) -> None:
    out = tables.on_page_markdown("<!-- bench demo case=a | robots rate share:pct rate:%+.1f -->", None, None, None)
    assert "| robots | rate | share | rate |" in out
    assert "| 1 | 1,235 | 99.99 % | +1234.6 |" in out
    assert "case" not in out.split("\n")[0] and "| 10 |" not in out
    assert "`make bench QUICK=1` on a 2-core machine (Test CPU), short runs: `python benchmarks/demo.py --fast`" in out


def test_a_key_only_some_lines_have_reads_a_dash(bench_data: Path) -> None:
    out = tables.on_page_markdown("<!-- bench demo | case share -->", None, None, None)
    assert "| b | — |" in out


def test_a_bare_key_selects_the_lines_that_have_it(bench_data: Path) -> None:
    out = tables.on_page_markdown("<!-- bench demo share | case -->", None, None, None)
    assert "| a |" in out and "| b |" not in out


@pytest.mark.parametrize("marker", [
    "<!-- bench missing | robots -->",        # no data file
    "<!-- bench demo | speed -->",            # no line has the key
    "<!-- bench demo case=z | robots -->",    # no line matches
])
def test_a_table_without_its_data_fails_the_build(bench_data: Path, marker: str) -> None:
    with pytest.raises(PluginError):
        tables.on_page_markdown(marker, None, None, None)


def _curve(folder: Path, rows: list[dict]) -> None:
    (folder / "tiny.jsonl").write_text("".join(json.dumps(row) + "\n" for row in rows))
    (folder / "tiny.command").write_text("python examples/train_ppo.py --steps 20\n")


def test_a_learning_curve_is_drawn_from_its_evaluations(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _curve(tmp_path, [
        {"env_steps": 10, "episodes": 4, "success_rate": 0.0, "collision_rate": 0.5, "wall_s": 1.0},
        {"env_steps": 20, "episodes": 4, "success_rate": 0.75, "collision_rate": 0.25, "wall_s": 2.0},
        {"env_steps": 20, "episodes": 8, "success_rate": 0.875, "collision_rate": 0.125, "wall_s": 3.0, "final": True},
    ])
    monkeypatch.setattr(tables, "TRAIN", tmp_path)
    out = tables.on_page_markdown("before\n<!-- curve tiny -->\nafter", None, None, None)
    svg = out[out.index("<svg"):out.index("</svg>")]
    success, collisions = re.findall(r'points="([^"]+)"', svg)
    # Two evaluations, two points per line; the final evaluation is the text under the plot, not a point.
    assert len(success.split()) == len(collisions.split()) == 2
    (x0, y0), (x1, y1) = (map(float, point.split(",")) for point in success.split())
    assert x0 < x1 and y1 < y0  # later and higher: 0 % at the bottom, 75 % above it
    assert "success 88 %, collisions 12 %, after 20 env steps" in out and "over 8 unseen seeds" in out
    assert "`python examples/train_ppo.py --steps 20`" in out and out.startswith("before") and out.endswith("after")


def test_a_curve_without_its_final_evaluation_fails_the_build(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _curve(tmp_path, [{"env_steps": 10, "episodes": 4, "success_rate": 0.0, "collision_rate": 0.5, "wall_s": 1.0}])
    monkeypatch.setattr(tables, "TRAIN", tmp_path)
    with pytest.raises(PluginError):
        tables.on_page_markdown("<!-- curve tiny -->", None, None, None)


def test_the_api_reference_has_a_page_per_package_in_layer_order() -> None:
    on_disk = {path.parent.name for path in (REPO / "stage_sim").glob("*/__init__.py")}
    layers = re.search(r"contract:layers\].*?layers =\n(.*?)\n\n", (REPO / ".importlinter").read_text(), re.DOTALL)
    order = [name.strip().removeprefix("stage_sim.") for line in layers[1].splitlines() for name in line.split("|")]
    assert set(api.packages()) == on_disk | {"backend"}  # a layer that is one module
    assert [name for name in api.packages() if name in order] == order
    page = api.package_page("sim")
    assert "::: stage_sim.sim.simulation" in page and "::: stage_sim.sim\n" in page


def test_the_nav_gets_the_api_pages() -> None:
    config = type("Config", (), {"nav": [{"Home": "index.md"}, {"API reference": []}]})()
    api.on_config(config)
    section = config.nav[1]["API reference"]
    assert section[0] == "api/index.md" and {"stage_sim.sim": "api/sim.md"} in section


def test_sphinx_roles_in_docstrings_show_as_code() -> None:
    text = "Walks as :func:`~stage_sim.sensing.region_jumps.stage_jump` does, see :mod:`stage_sim.sim`."
    assert roles.ROLE.sub(roles.plain, text) == "Walks as `stage_jump` does, see `stage_sim.sim`."
