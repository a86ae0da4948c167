"""MkDocs hook: the tables of measured figures, made at build time from the benchmark scripts' JSON lines.

`make bench` writes each script's JSON lines to ``docs/data/bench/<script>.jsonl`` and the command that
printed them to ``<script>.command`` (``machine.json``: the machine's cores and CPU, and whether the short runs
of ``make bench QUICK=1`` made them). A page asks for a table with an HTML comment::

    <!-- bench simulate beams=240 kernels=numba | robots threads realtime_factor peak_rss_mb:MB -->

that is: the data file, then filters that must all hold (``key=value``, or a bare ``key`` the line must
have), then after ``|`` the columns, each a key of the JSON lines with an optional format (``pct``: a share
shown in percent; ``M``: in millions; ``%SPEC``: Python's format SPEC, e.g. ``%+.4f``; any other word: a
unit put after the number). The table is followed by the commands that produced it, so no figure is typed
by hand. A missing file, a key no selected line has, or an empty selection fails the build; a key only some
lines have reads "—" in the others.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from mkdocs.config.defaults import MkDocsConfig
from mkdocs.exceptions import PluginError
from mkdocs.structure.files import Files
from mkdocs.structure.pages import Page

DATA = Path(__file__).resolve().parents[1] / "docs" / "data" / "bench"
MARKER = re.compile(r"<!-- bench (?P<spec>[^|>]+)\|(?P<columns>[^>]+)-->")


def read_lines(name: str) -> list[dict[str, Any]]:
    path = DATA / f"{name}.jsonl"
    if not path.is_file():
        raise PluginError(f"no benchmark data {path}: run `make bench`")
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def cell(value: Any, fmt: str | None) -> str:
    if value is None:
        return "—"
    if fmt == "pct":
        return f"{100 * value:.2f} %"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, list):
        return " × ".join(map(str, value)) if value else "none"
    if fmt == "M":
        return f"{value / 1e6:.3g} M"
    if fmt and fmt.startswith("%"):
        return format(value, fmt[1:])
    text = number(value) if isinstance(value, (int, float)) else str(value)
    return f"{text} {fmt}" if fmt else text


def number(value: float) -> str:
    """Four significant digits below 100, whole numbers with thousands separators from there on."""
    return f"{value:,.0f}" if abs(value) >= 100 else f"{value:.4g}"


def provenance(name: str) -> str:
    """Which commands, run by which `make` target, on what machine, made the file's lines. A file measured by a
    target of its own (``make bench-peers``) has its own ``<name>.machine.json``, with that target and a note
    on the run; the others share ``machine.json`` of ``make bench``."""
    own = DATA / f"{name}.machine.json"
    machine = json.loads((own if own.is_file() else DATA / "machine.json").read_text())
    make = machine.get("make") or ("make bench QUICK=1" if machine["quick"] else "make bench")
    commands = "; ".join(f"`{line}`" for line in (DATA / f"{name}.command").read_text().splitlines() if line)
    note = f" ({machine['note']})" if machine.get("note") else ""
    return (f"*Measured by `{make}` on a {machine['cores']}-core machine ({machine['cpu']})"
            f"{', short runs' if machine['quick'] else ''}{note}: {commands}.*")


def table(spec: str, columns: str) -> str:
    name, *filters = spec.split()
    wanted = dict(item.split("=", 1) for item in filters if "=" in item)
    present = [item for item in filters if "=" not in item]
    rows = [row for row in read_lines(name)
            if all(str(row.get(k)) == v for k, v in wanted.items()) and all(k in row for k in present)]
    if not rows:
        raise PluginError(f"bench table {name} {filters}: no line matches")
    keys = [column.partition(":")[::2] for column in columns.split()]
    missing = {key for key, _ in keys if all(key not in row for row in rows)}
    if missing:
        raise PluginError(f"bench table {name}: no line has {sorted(missing)}")
    head = "| " + " | ".join(key for key, _ in keys) + " |\n|" + "---|" * len(keys) + "\n"
    body = "".join("| " + " | ".join(cell(row.get(key), fmt or None) for key, fmt in keys) + " |\n" for row in rows)
    return head + body + "\n" + provenance(name) + "\n"


def on_page_markdown(markdown: str, page: Page, config: MkDocsConfig, files: Files) -> str:
    return MARKER.sub(lambda match: table(match["spec"], match["columns"]), markdown)
