"""The argument parser: every command, option and default, in one place."""

from __future__ import annotations

import argparse
from pathlib import Path

from archmetrics import __version__
from archmetrics.cli.common import Parser
from archmetrics.cli.docs import docs_root
from archmetrics.cli.options import (
    add_allow_raised_limits,
    add_baseline,
    add_chart,
    add_config_from,
    add_exclude,
    add_format,
    add_group,
    add_history,
    add_locations,
    add_max_rows,
    add_output,
)
from archmetrics.reports.formats import Grouping, OutputFormat


def docs_epilog() -> str:
    """Where the installed pages are, for --help (they ship inside the wheel)."""
    root = docs_root()
    where = f"installed in {root}" if root is not None else "missing from this installation"
    return (
        f"Docs: {where}: glossary.md (what each number means), metrics.md (what is counted),"
        " json.md (the JSON contract), ci.md (CI, pre-commit, code scanning, choosing gates);"
        " `archmetrics docs [TOPIC]` lists them or prints one."
    )


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="archmetrics",
        description="Measure what it costs to integrate new code into an existing system: "
        "coupling, logical LOC, McCabe complexity and the complexity change cost E "
        "(Hestand 2011), per location (base, new, framework).",
        epilog="Exit status: 0 measured (all gates hold), 1 a gate failed, 2 could not measure. "
        + docs_epilog(),
    )
    parser.add_argument("--version", action="version", version=f"archmetrics {__version__}")
    parser.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        help="detail on stderr: cache hits, time taken; the traceback of an unexpected error",
    )
    commands = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    scan = commands.add_parser(
        "scan", help="λ, SLOC, v_g per file and function; coupling per element; every link"
    )
    scan.add_argument("paths", nargs="*", type=Path, metavar="PATH", help="files or folders")
    scan.add_argument("--rev", help="measure this git revision instead of the files on disk")
    scan.add_argument("--by", choices=[g.value for g in Grouping], default="file")
    scan.add_argument(
        "--sample", action="store_true", help="scan the sample shipped with archmetrics"
    )
    scan.add_argument(
        "--fail-on",
        action="append",
        default=[],
        metavar="EXPR",
        help="a threshold, e.g. 'vg(function) > 15' or 'loc(file) > 1000 or vg(file) > 200';"
        " exit 1 when a function, file, element or the total fails it (repeatable)",
    )
    add_output(scan, [f.value for f in OutputFormat])
    add_baseline(scan)
    add_allow_raised_limits(scan)
    add_group(scan)
    baseline = commands.add_parser(
        "baseline",
        help="write the offenders of thresholds to a file, so that scan and diff --baseline"
        " fail only on new or worsened ones",
    )
    baseline.add_argument("paths", nargs="*", type=Path, metavar="PATH", help="files or folders")
    baseline.add_argument("--rev", help="measure this git revision instead of the files on disk")
    baseline.add_argument(
        "--fail-on", action="append", default=[], metavar="EXPR",
        help="a threshold whose offenders to record, e.g. 'vg(function) > 15' (repeatable;"
        " default: the configuration's function and file gates)",
    )  # fmt: skip
    baseline.add_argument(
        "--output", "-o", type=Path,
        help="the baseline file to write (default: archmetrics-baseline.json)",
    )  # fmt: skip
    baseline.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    baseline.add_argument("--jobs", "-j", type=int, default=0, help="parser processes")
    baseline.add_argument("--no-cache", action="store_true", help="parse everything, store nothing")
    baseline.add_argument("--cache-path", type=Path, help="the facts cache file to use")
    add_exclude(baseline)
    add_allow_raised_limits(baseline)
    diff = commands.add_parser(
        "diff", help="the chapter-6 metrics of a change: Γ, scale factors, ΔVg, cost E per location"
    )
    diff.add_argument(
        "--base",
        default="HEAD",
        help="REV, EMPTY, WORKTREE or INDEX (default HEAD); A...B compares B with the merge"
        " base of A and B, as git diff A...B does (a pull request's own changes); A..B is A"
        " against B",
    )
    diff.add_argument(
        "--head", default=None, help="REV, EMPTY, WORKTREE or INDEX (default WORKTREE)"
    )
    diff.add_argument(
        "--merge-base",
        action="store_true",
        help="compare --head with the merge base of --base and --head (as --base A...B)",
    )
    diff.add_argument("files", nargs="*", metavar="FILE", help=argparse.SUPPRESS)
    diff.add_argument("--repo", "-C", type=Path, default=Path("."), help="the repository")
    diff.add_argument(
        "--from-pre-commit",
        action="store_true",
        help="when pre-commit sets PRE_COMMIT_FROM_REF and PRE_COMMIT_TO_REF (pre-commit run "
        "--from-ref A --to-ref B), compare those instead of --base and --head",
    )
    add_locations(diff)
    add_chart(diff)
    add_output(diff, [f.value for f in OutputFormat])
    add_max_rows(diff)
    add_group(diff)
    add_baseline(diff)
    add_allow_raised_limits(diff)
    add_config_from(diff, "--base's", "--head's")
    series = commands.add_parser(
        "series", help="each stage measured against the one before (baseline, first, second)"
    )
    series.add_argument("revisions", nargs="+", metavar="REV", help="the stages, oldest first")
    series.add_argument("--labels", help="comma-separated stage names, e.g. baseline,first,second")
    series.add_argument("--root", default="EMPTY", help="what the first stage is measured against")
    series.add_argument("--repo", "-C", type=Path, default=Path("."), help="the repository")
    add_locations(series)
    add_chart(series)
    add_output(series, [f.value for f in OutputFormat])
    add_max_rows(series)
    add_allow_raised_limits(series)
    add_config_from(series, "the first stage's base (--root, or the first REV)", "the last REV's")
    compare = commands.add_parser(
        "compare", help="the same series for several repositories side by side"
    )
    compare.add_argument("repos", nargs="+", metavar="NAME=PATH", help="e.g. soa=./wdb-soa")
    compare.add_argument(
        "--revisions",
        help="comma-separated stage revisions (default: each repo's tags, oldest first)",
    )
    compare.add_argument("--labels", help="comma-separated stage names")
    compare.add_argument("--root", default="EMPTY", help="what the first stage is measured against")
    add_locations(compare)
    add_chart(compare)
    add_output(compare, [f.value for f in OutputFormat])
    add_allow_raised_limits(compare)
    add_config_from(compare, "each repository's first stage's base", "its last revision's")
    add_history(commands)
    estimate = commands.add_parser(
        "estimate",
        help="price an integration before doing it: each architecture of a plan (TOML) or"
        " sketch estimated against a measured base, ranked (docs/estimate.md)",
    )
    estimate.add_argument("plan", metavar="PLAN", help="the plan file (TOML, docs/estimate.md)")
    estimate.add_argument(
        "--base", default="HEAD", help="the revision the plan applies to (default HEAD)"
    )
    estimate.add_argument("--repo", "-C", type=Path, default=Path("."), help="the repository")
    estimate.add_argument(
        "--actual",
        action="store_true",
        help="after the integration: compare the estimate with the measured --base..--head,"
        " per location and per element, and report each figure's error",
    )
    estimate.add_argument("--head", help="with --actual: the revision the integration is in")
    estimate.add_argument(
        "--stage", help="with --actual: the stage to compare (default: the plan's only stage)"
    )
    estimate.add_argument(
        "--architecture",
        action="append",
        default=[],
        metavar="NAME",
        help="estimate only this architecture of the plan (repeatable; default: all)",
    )
    add_locations(estimate)
    add_chart(estimate)
    add_output(estimate, [f.value for f in OutputFormat])
    add_allow_raised_limits(estimate)
    add_config_from(estimate, "--base's", "--head's (with --actual; else the work tree's)")
    replicate = commands.add_parser(
        "replicate", help="the thesis's study on the bundled subjects: report, findings, charts"
    )
    replicate.add_argument(
        "--out", type=Path, default=Path("archmetrics-study"), help="where to write the report"
    )
    replicate.add_argument(
        "--subject", action="append", default=[], help="only this subject (wdb, pragmatics, legacy)"
    )
    replicate.add_argument(
        "--keep-repos", type=Path, metavar="DIR", help="build the subjects' repositories here"
    )
    replicate.add_argument("--no-charts", action="store_true", help="skip the charts")
    replicate.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    replicate.add_argument("--jobs", "-j", type=int, default=0, help="parser processes")
    replicate.add_argument(
        "--no-cache", action="store_true", help="parse everything, store nothing"
    )
    replicate.add_argument("--cache-path", type=Path, help="the facts cache file to use")
    rules = commands.add_parser("rules", help="the dynamic-coupling rules in force")
    rules.add_argument("--format", choices=["table", "markdown", "json"], default="table")
    rules.add_argument("--repo", "-C", type=Path, default=Path("."), help="whose config to read")
    graph = commands.add_parser("graph", help="the element graph: who depends on and talks to whom")
    graph.add_argument("paths", nargs="*", type=Path, metavar="PATH", help="files or folders")
    graph.add_argument("--rev", help="the git revision to draw instead of the files on disk")
    add_format(graph, ["dot", "mermaid", "json"])
    graph.add_argument(
        "--output",
        "-o",
        type=Path,
        help="write the graph to FILE (.dot, .mmd or .json picks the format unless --format)",
    )
    graph.add_argument("--jobs", "-j", type=int, default=0, help="parser processes (0: per core)")
    graph.add_argument("--no-cache", action="store_true", help="parse everything, store nothing")
    graph.add_argument("--cache-path", type=Path, help="the facts cache file to use")
    graph.add_argument(
        "--view",
        choices=["elements", "computation"],
        default=None,
        help="elements: who depends on and talks to whom; computation: elements and the"
        " topics, services, actions and plugins between them, as rqt_graph draws a ROS graph"
        " (default: computation when the tree has ROS sites, else elements)",
    )
    add_exclude(graph)
    add_group(graph)
    add_allow_raised_limits(graph)
    docs = commands.add_parser(
        "docs", help="the documentation installed with archmetrics: list the pages, print one"
    )
    docs.add_argument("topic", nargs="?", metavar="TOPIC", help="a page, e.g. ci, json, metrics")
    docs.add_argument("--path", action="store_true", help="print the page's file, not its text")
    cache = commands.add_parser("cache", help="the facts cache: where it is, how big; clear it")
    cache.add_argument("action", choices=["info", "clear"])
    cache.add_argument("--cache-path", type=Path, help="the facts cache file")
    for command in commands.choices.values():  # -v also after the command's name
        command.add_argument(
            "-v",
            "--verbose",
            action="store_true",
            default=argparse.SUPPRESS,
            help=argparse.SUPPRESS,
        )
    return parser
