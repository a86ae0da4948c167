"""MkDocs hook: the API reference, one page per package of stage_sim, listing the modules found on disk.

The pages are generated at build time (never committed), so the reference follows the code when modules are
added, renamed or moved: each page holds one mkdocstrings block (``::: stage_sim.<package>.<module>``) per
module, and the nav's "API reference" section gets one entry per package, in layer order (top to bottom).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

from docs_rst_roles import ROLE, plain  # beside this hook: MkDocs puts a hook's folder on sys.path
from mkdocs.config.defaults import MkDocsConfig
from mkdocs.structure.files import File, Files

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "stage_sim"
SECTION = "API reference"


def layer_order() -> list[str]:
    """The layers top to bottom, read from .importlinter's layers contract (their one home)."""
    block = re.search(r"contract:layers\].*?layers =\n(.*?)\n\n", (REPO / ".importlinter").read_text(), re.DOTALL)
    return [name.strip().removeprefix("stage_sim.") for line in block[1].splitlines() for name in line.split("|")]


def packages() -> list[str]:
    """stage_sim's sub-packages on disk and its top-level modules that are layers, in layer order (a package
    not in the layers contract goes last)."""
    layers = layer_order()
    found = [path.parent.name for path in PACKAGE.glob("*/__init__.py")]
    found += [path.stem for path in PACKAGE.glob("*.py") if path.stem in layers]
    rank = {name: index for index, name in enumerate(layers)}
    return sorted(found, key=lambda name: (rank.get(name, len(rank)), name))


def _source(package: str) -> Path:
    folder = PACKAGE / package
    return folder / "__init__.py" if folder.is_dir() else PACKAGE / f"{package}.py"


def modules(package: str) -> list[str]:
    """The package's modules (its ``__init__`` first), as dotted names; ``__main__`` is a script, not API."""
    folder = PACKAGE / package
    names = sorted(path.stem for path in folder.glob("*.py") if path.stem not in ("__init__", "__main__"))
    return [f"stage_sim.{package}"] + [f"stage_sim.{package}.{name}" for name in names]


def summary(package: str) -> str:
    """The first line of the package's docstring: what the package holds."""
    docstring = ast.get_docstring(ast.parse(_source(package).read_text())) or ""
    return ROLE.sub(plain, docstring.strip().splitlines()[0]) if docstring.strip() else ""


def package_page(package: str) -> str:
    blocks = [f"::: {name}\n    options:\n      show_root_heading: true\n      heading_level: 2\n"
              for name in modules(package)]
    return f"# stage_sim.{package}\n\n" + "\n".join(blocks)


def index_page() -> str:
    rows = "\n".join(f"| [`stage_sim.{name}`]({name}.md) | {summary(name)} |" for name in packages())
    return ("# API reference\n\nGenerated from the docstrings at every build, one page per package, in layer "
            "order (a package imports only the ones below it; see [Architecture](../architecture.md)). The "
            "public API is `from stage_sim import Simulation, load_world, load_world_text, WorldError, "
            "render`.\n\n| package | what it holds |\n|---|---|\n" + rows + "\n")


def on_config(config: MkDocsConfig) -> MkDocsConfig:
    """Fill the nav's API section with one entry per package."""
    for entry in config.nav or []:
        if isinstance(entry, dict) and SECTION in entry:
            entry[SECTION] = ["api/index.md"] + [{f"stage_sim.{name}": f"api/{name}.md"} for name in packages()]
    return config


def on_files(files: Files, config: MkDocsConfig) -> Files:
    files.append(File.generated(config, "api/index.md", content=index_page()))
    for name in packages():
        files.append(File.generated(config, f"api/{name}.md", content=package_page(name)))
    return files
