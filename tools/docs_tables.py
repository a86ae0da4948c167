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

A learning curve (``make train`` writes ``docs/data/train/<name>.jsonl``: one line per evaluation, the last one
the final evaluation) is asked for with ``<!-- curve NAME -->``: an SVG of success and collision rate against
env steps, drawn here from those lines, and the final result under it.
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
TRAIN = DATA.parent / "train"
MARKER = re.compile(r"<!-- bench (?P<spec>[^|>]+)\|(?P<columns>[^>]+)-->")
CURVE = re.compile(r"<!-- curve (?P<name>[\w-]+) -->")
#: The curve's plot: size and margins in SVG pixels.
WIDTH, HEIGHT, LEFT, RIGHT, TOP, BOTTOM = 640, 300, 56, 16, 16, 44


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


def learning_curve(name: str) -> str:
    """The SVG of the evaluations of ``TRAIN/<name>.jsonl`` and a line on the final one and its command."""
    path = TRAIN / f"{name}.jsonl"
    if not path.is_file():
        raise PluginError(f"no learning curve {path}: run `make train`")
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    points = [row for row in rows if not row.get("final")]
    final = [row for row in rows if row.get("final")]
    if not points or not final:
        raise PluginError(f"learning curve {path}: needs periodic evaluations and a final one")
    last = final[-1]
    command = (TRAIN / f"{name}.command").read_text().strip()
    return (curve_svg(points) + "\n\n"
            f"*Final evaluation over {last['episodes']} unseen seeds: success {100 * last['success_rate']:.0f} %, "
            f"collisions {100 * last['collision_rate']:.0f} %, after {last['env_steps']:,} env steps and "
            f"{last['wall_s']:,.0f} s of wall time (evaluations included). Made by `make train`: `{command}`.*\n")


def curve_svg(points: list[dict[str, Any]]) -> str:
    """Success (solid) and collision rate (dashed) against env steps, axes 0–max steps and 0–100 %."""
    span = max(row["env_steps"] for row in points)
    plot_w, plot_h = WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM

    def xy(steps: float, rate: float) -> str:
        return f"{LEFT + plot_w * steps / span:.1f},{TOP + plot_h * (1 - rate):.1f}"

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {WIDTH} {HEIGHT}" width="{WIDTH}" '
             f'height="{HEIGHT}" font-family="sans-serif" font-size="12" role="img" '
             'aria-label="success and collision rate against env steps">']
    for tick in (0.0, 0.25, 0.5, 0.75, 1.0):
        y = TOP + plot_h * (1 - tick)
        parts.append(f'<line x1="{LEFT}" y1="{y:.1f}" x2="{WIDTH - RIGHT}" y2="{y:.1f}" stroke="#ddd"/>'
                     f'<text x="{LEFT - 6}" y="{y + 4:.1f}" text-anchor="end">{100 * tick:.0f} %</text>')
    for k in range(5):
        steps = span * k / 4
        x = LEFT + plot_w * k / 4
        parts.append(f'<text x="{x:.1f}" y="{HEIGHT - BOTTOM + 16}" text-anchor="middle">{steps / 1000:,.0f}k</text>')
    parts.append(f'<text x="{LEFT + plot_w / 2:.1f}" y="{HEIGHT - 6}" text-anchor="middle">env steps</text>')
    for key, style, label in (("success_rate", "", "success"), ("collision_rate", ' stroke-dasharray="5,4"',
                                                                   "collisions")):
        line = " ".join(xy(row["env_steps"], row[key]) for row in points)
        parts.append(f'<polyline fill="none" stroke="currentColor" stroke-width="2"{style} points="{line}">'
                     f"<title>{label}</title></polyline>")
    parts.append("</svg>")
    return "".join(parts)


def on_page_markdown(markdown: str, page: Page, config: MkDocsConfig, files: Files) -> str:
    markdown = CURVE.sub(lambda match: learning_curve(match["name"]), markdown)
    return MARKER.sub(lambda match: table(match["spec"], match["columns"]), markdown)
