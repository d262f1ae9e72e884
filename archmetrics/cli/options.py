"""The options several commands share (output and format, locations, excludes, charts,
baselines, limits, whose configuration) and the ``history`` command's own."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from archmetrics.cli.common import Parser, UsageError
from archmetrics.reports.charts import chart_kinds

# What a suffix of --output means when --format is not given (an explicit --format wins).
SUFFIX_FORMATS = {
    ".json": "json",
    ".sarif": "sarif",
    ".md": "markdown",
    ".markdown": "markdown",
    ".csv": "csv",
    ".txt": "table",
    ".dot": "dot",
    ".gv": "dot",
    ".mmd": "mermaid",
}


def add_output(parser: argparse.ArgumentParser, formats: Sequence[str]) -> None:
    add_format(parser, formats)
    parser.add_argument(
        "--output",
        "-o",
        type=Path,
        help="write the report to FILE (.json, .md, .csv or .sarif picks the format unless"
        " --format)",
    )
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    parser.add_argument("--jobs", "-j", type=int, default=0, help="parser processes (0: per core)")
    parser.add_argument("--no-cache", action="store_true", help="parse everything, store nothing")
    parser.add_argument("--cache-path", type=Path, help="the facts cache file to use")
    add_exclude(parser)


def add_allow_raised_limits(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--allow-raised-limits",
        action="store_true",
        help="let the configuration raise [limits] above their defaults (up to their ceilings);"
        " without it a raised limit is put back to its default, with a warning",
    )


def add_config_from(parser: argparse.ArgumentParser, base: str, head: str) -> None:
    parser.add_argument(
        "--config-from",
        default="base",
        metavar="base|head|FILE",
        help=f"whose configuration decides what is measured and the gates: {base} (the"
        f" default: a pull request cannot change them), {head}, or a TOML file of the"
        " runner's (docs/ci.md)",
    )


def add_group(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--group",
        choices=["component", "file", "package", "node"],
        default=None,
        help="what one element is: a C/C++ header and its source (component, the default), a"
        " file, a ROS package (the folder holding package.xml) or a ROS node's files",
    )


def add_exclude(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--exclude",
        action="append",
        default=[],
        metavar="GLOB",
        help="leave out the files this glob matches, after the configured `exclude` (repeatable;"
        " each one excluded is listed in the report)",
    )


def add_format(parser: argparse.ArgumentParser, formats: Sequence[str]) -> None:
    default = formats[0]
    parser.add_argument(
        "--format", choices=formats, default=None, help=f"output format (default: {default})"
    )
    parser.set_defaults(format_choices=tuple(formats), format_default=default)


def settle_format(args: argparse.Namespace) -> None:
    """``args.format`` when --format was not given: what the suffix of --output names, or
    the command's default for a file with no suffix (or no file). A suffix that names none
    of the command's formats (``report.html``) is a usage error, never a table written
    under a name that says otherwise."""
    if getattr(args, "format", "") is not None or not hasattr(args, "format_default"):
        return
    output = getattr(args, "output", None)
    suffix = output.suffix.lower() if output is not None else ""
    named = SUFFIX_FORMATS.get(suffix)
    if suffix and named not in args.format_choices:
        known = ", ".join(s for s, f in SUFFIX_FORMATS.items() if f in args.format_choices)
        raise UsageError(
            f"{output}: {suffix} names no format of this command (endings: {known});"
            f" give --format ({', '.join(args.format_choices)})"
        )
    args.format = named or args.format_default


def add_chart(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--chart", type=Path, metavar="FILE", help="also draw a chart into FILE (.png or .svg)"
    )
    parser.add_argument(
        "--chart-kind", default="cost", choices=chart_kinds(), help="which chart (default: cost)"
    )


def add_baseline(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--baseline",
        type=Path,
        metavar="FILE",
        help="offenders already known (archmetrics baseline): thresholds and function gates"
        " fail only on new offenders and on offenders that got worse",
    )


def add_max_rows(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--max-rows",
        type=int,
        metavar="N",
        help="Markdown: at most N changed elements, the most changed first (0: all; default: "
        "as many as fit in a pull-request comment, 65,536 characters)",
    )


def add_locations(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--new", action="append", default=[], metavar="GLOB", help="new location")
    parser.add_argument(
        "--framework", action="append", default=[], metavar="GLOB", help="framework location"
    )
    parser.add_argument(
        "--fail-on",
        action="append",
        default=[],
        metavar="EXPR",
        help="a gate, e.g. 'cost(new) > 20'; exit 1 when it fails (repeatable)",
    )
    parser.add_argument(
        "--dynamic-pre-zero",
        action="store_true",
        help="take d_a, d_e before integration as 0 (the thesis's convention, p. 100)",
    )


def add_history(commands: argparse._SubParsersAction[Parser]) -> None:
    history = commands.add_parser(
        "history",
        help="every commit of a branch against its first parent: Γ, ΔVg', E per location,"
        " the costliest commits and the elements where integration cost accumulates",
    )
    history.add_argument(
        "range", nargs="?", default="HEAD", metavar="REV_RANGE",
        help="the commits, as git log takes them (default HEAD: its whole history)",
    )  # fmt: skip
    history.add_argument(
        "--first-parent", action=argparse.BooleanOptionalAction, default=True,
        help="follow only first parents, each merge one integrated branch (default: on)",
    )  # fmt: skip
    history.add_argument(
        "--merges", action="store_true", help="only merge commits, each against its first parent"
    )
    history.add_argument("--since", metavar="DATE", help="commits after DATE (as git reads it)")
    history.add_argument("--until", metavar="DATE", help="commits before DATE")
    history.add_argument(
        "--max-count", "-n", type=int, metavar="N", help="only the newest N commits"
    )
    history.add_argument("--repo", "-C", type=Path, default=Path("."), help="the repository")
    history.add_argument(
        "--top", type=int, default=10, metavar="N",
        help="how many costliest commits and hotspot elements to show (default 10)",
    )  # fmt: skip
    history.add_argument("--element", metavar="NAME", help="also show this element's own trend")
    history.add_argument(
        "--scheduler", metavar="ADDRESS",
        help="run on the Dask cluster whose scheduler is at ADDRESS, e.g. tcp://host:8786"
        " (needs archmetrics[dask]; docs/history.md)",
    )  # fmt: skip
    history.add_argument(
        "--workers", type=int, metavar="N", help="run on a local Dask cluster of N workers"
    )
    add_locations(history)
    add_allow_raised_limits(history)
    add_chart(history)
    add_output(history, ["table", "json", "markdown", "csv"])
