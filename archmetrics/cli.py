"""The ``archmetrics`` command line: flags become a request, one use case runs, a report prints.

Exit status: 0 measured (and every gate holds), 1 a gate failed, 2 could not measure (bad usage,
unknown revision, bad configuration) with a one-line error and no traceback.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import NoReturn

from archmetrics import __version__
from archmetrics.app.diff import DiffRequest, run_diff
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.app.scan import ScanRequest, run_scan
from archmetrics.changeset.gates import GateError
from archmetrics.changeset.locations import BadPattern
from archmetrics.config import ConfigError, Settings, load_settings
from archmetrics.coupling.rules import RulePackError
from archmetrics.parsers import UnknownLanguage
from archmetrics.reports.formats import Grouping, OutputFormat, render_diff, render_scan
from archmetrics.sources import SourceError
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.cache import default_path as cache_default_path

EXIT_OK, EXIT_GATE, EXIT_USAGE = 0, 1, 2


class UsageError(Exception):
    """Bad usage found after parsing (a missing file, a bad value)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see --help)\n")


class RichProgress:
    """A rich progress bar on stderr, for runs over many files in a terminal."""

    def __init__(self) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeRemainingColumn

        self._bar = Progress(
            "[progress.description]{task.description}",
            BarColumn(),
            MofNCompleteColumn(),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=True,
        )
        self._task: object = None

    def start(self, description: str, total: int) -> None:
        if total >= 20:
            self._bar.start()
            self._task = self._bar.add_task(description, total=total)

    def advance(self, count: int = 1) -> None:
        if self._task is not None:
            self._bar.advance(self._task, count)  # type: ignore[arg-type]

    def stop(self) -> None:
        if self._task is not None:
            self._bar.stop()
            self._task = None


def _progress(fmt: OutputFormat, quiet: bool) -> Progress:
    if quiet or fmt is not OutputFormat.TABLE or not sys.stderr.isatty():
        return NoProgress()
    return RichProgress()


def sample_path() -> Path:
    """The small sample tree shipped inside the package (the default main job's input)."""
    return Path(__file__).parent / "data" / "sample"


def _add_output(parser: argparse.ArgumentParser, formats: Sequence[str]) -> None:
    parser.add_argument("--format", choices=formats, default=formats[0], help="output format")
    parser.add_argument("--output", "-o", type=Path, help="write the report to FILE")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    parser.add_argument("--jobs", "-j", type=int, default=0, help="parser processes (0: per core)")
    parser.add_argument("--no-cache", action="store_true", help="parse everything, store nothing")
    parser.add_argument("--cache-path", type=Path, help="the facts cache file to use")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="archmetrics", description=__doc__.split("\n")[0])
    parser.add_argument("--version", action="version", version=f"archmetrics {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    scan = commands.add_parser("scan", help="λ, SLOC and v_g per file and function")
    scan.add_argument("paths", nargs="*", type=Path, metavar="PATH", help="files or folders")
    scan.add_argument("--rev", help="measure this git revision instead of the files on disk")
    scan.add_argument("--by", choices=[g.value for g in Grouping], default="file")
    scan.add_argument(
        "--sample", action="store_true", help="scan the sample shipped with archmetrics"
    )
    _add_output(scan, [f.value for f in OutputFormat])
    diff = commands.add_parser(
        "diff", help="the chapter-6 metrics of a change: Γ, scale factors, ΔVg, cost E per location"
    )
    diff.add_argument("--base", default="HEAD", help="REV, EMPTY, WORKTREE or INDEX (default HEAD)")
    diff.add_argument(
        "--head", default="WORKTREE", help="REV, EMPTY, WORKTREE or INDEX (default WORKTREE)"
    )
    diff.add_argument("--repo", "-C", type=Path, default=Path("."), help="the repository")
    diff.add_argument("--new", action="append", default=[], metavar="GLOB", help="new location")
    diff.add_argument(
        "--framework", action="append", default=[], metavar="GLOB", help="framework location"
    )
    diff.add_argument(
        "--fail-on",
        action="append",
        default=[],
        metavar="EXPR",
        help="a gate, e.g. 'cost(new) > 20'; exit 1 when it fails (repeatable)",
    )
    diff.add_argument(
        "--dynamic-pre-zero",
        action="store_true",
        help="take d_a, d_e before integration as 0 (the thesis's convention, p. 100)",
    )
    _add_output(diff, [f.value for f in OutputFormat])
    rules = commands.add_parser("rules", help="the dynamic-coupling rules in force")
    rules.add_argument("--format", choices=["table", "markdown", "json"], default="table")
    rules.add_argument("--repo", "-C", type=Path, default=Path("."), help="whose config to read")
    graph = commands.add_parser("graph", help="the element graph: who depends on and talks to whom")
    graph.add_argument("paths", nargs="*", type=Path, metavar="PATH", help="files or folders")
    graph.add_argument("--rev", help="the git revision to draw instead of the files on disk")
    graph.add_argument("--format", choices=["dot", "mermaid", "json"], default="dot")
    graph.add_argument("--output", "-o", type=Path, help="write the graph to FILE")
    graph.add_argument("--jobs", "-j", type=int, default=0, help="parser processes (0: per core)")
    graph.add_argument("--no-cache", action="store_true", help="parse everything, store nothing")
    graph.add_argument("--cache-path", type=Path, help="the facts cache file to use")
    cache = commands.add_parser("cache", help="the facts cache: where it is, how big; clear it")
    cache.add_argument("action", choices=["info", "clear"])
    cache.add_argument("--cache-path", type=Path, help="the facts cache file")
    return parser


def _repo_root(path: Path) -> Path:
    """The top of the git repository holding ``path``, or its folder outside git."""
    from archmetrics.sources import git

    folder = path if path.is_dir() else path.parent
    if git.is_repository(folder):
        return git.toplevel(git.open_repository(folder))
    return folder


def _settings_for(path: Path) -> Settings:
    return load_settings(_repo_root(path))


def _emit(text: str, output: Path | None) -> None:
    if output is None:
        sys.stdout.write(text)
        return
    try:
        output.write_text(text, encoding="utf-8")
    except OSError as error:
        raise UsageError(f"{output}: cannot write: {error.strerror}") from error


@contextmanager
def _facts_cache(args: argparse.Namespace, settings: Settings) -> Iterator[FactsCache | None]:
    """The cache the flags and settings ask for (none with --no-cache or cache = false)."""
    if getattr(args, "no_cache", False) or not settings.cache:
        yield None
        return
    path = args.cache_path or (Path(settings.cache_path) if settings.cache_path else None)
    with FactsCache(path or cache_default_path()) as cache:
        for notice in cache.notices:
            print(f"archmetrics: warning: {notice}", file=sys.stderr)
        yield cache


def _cache(args: argparse.Namespace) -> int:
    settings = _settings_for(Path.cwd())
    with _facts_cache(args, settings) as cache:
        assert cache is not None
        if args.action == "clear":
            print(f"removed {cache.clear()} entries from {cache.path}")
            return EXIT_OK
        info = cache.info()
        print(f"path:        {info.path}")
        print(f"entries:     {info.entries} ({info.current_entries} from this parser version)")
        print(f"size:        {info.bytes / 1e6:.1f} MB")
        print(f"fingerprint: {info.fingerprint}")
    return EXIT_OK


def _scan(args: argparse.Namespace) -> int:
    paths: tuple[Path, ...] = tuple(args.paths)
    if args.sample:
        if paths or args.rev:
            raise UsageError("--sample takes no PATH and no --rev")
        paths = (sample_path(),)
    settings = _settings_for(paths[0] if paths else Path.cwd())
    fmt = OutputFormat(args.format)
    request = ScanRequest(
        paths=paths, rev=args.rev, settings=settings, jobs=args.jobs, plain_directory=args.sample
    )
    with _facts_cache(args, settings) as cache:
        report = run_scan(request, _progress(fmt, args.quiet), cache)
    _emit(render_scan(report, fmt, Grouping(args.by)), args.output)
    return EXIT_OK


def _rules(args: argparse.Namespace) -> int:
    from archmetrics.app.coupling import rule_set
    from archmetrics.coupling.ruletable import rule_rows, rules_markdown
    from archmetrics.reports.json_report import dumps
    from archmetrics.reports.table_report import rows_table, to_text

    settings = _settings_for(args.repo)
    ruleset = rule_set(settings, _repo_root(args.repo))
    if args.format == "markdown":
        sys.stdout.write(rules_markdown(ruleset))
        return EXIT_OK
    rows = rule_rows(ruleset)
    fields = ("pack", "rule", "language", "match", "kind", "role", "endpoint", "requires")
    if args.format == "json":
        document = {
            "schema": "archmetrics.rules/1",
            "rules": [{f: getattr(r, f) for f in fields} for r in rows],
        }
        sys.stdout.write(dumps(document))
        return EXIT_OK
    cells = [[getattr(r, f) for f in fields] for r in rows]
    sys.stdout.write(to_text(rows_table(f"{len(rows)} rules in force", fields, cells, 8)))
    return EXIT_OK


def _graph(args: argparse.Namespace) -> int:
    from archmetrics.reports.graph import render

    paths: tuple[Path, ...] = tuple(args.paths)
    settings = _settings_for(paths[0] if paths else Path.cwd())
    request = ScanRequest(paths=paths, rev=args.rev, settings=settings, jobs=args.jobs)
    with _facts_cache(args, settings) as cache:
        report = run_scan(request, NoProgress(), cache)
    assert report.coupling is not None
    _emit(render(report.coupling.graph, args.format), args.output)
    return EXIT_OK


def _diff(args: argparse.Namespace) -> int:
    settings = _settings_for(args.repo)
    fmt = OutputFormat(args.format)
    request = DiffRequest(
        root=args.repo,
        base=args.base,
        head=args.head,
        settings=settings,
        new=tuple(args.new),
        framework=tuple(args.framework),
        gates=tuple(args.fail_on),
        jobs=args.jobs,
        dynamic_pre_zero=args.dynamic_pre_zero,
    )
    with _facts_cache(args, settings) as cache:
        report = run_diff(request, _progress(fmt, args.quiet), cache)
    _emit(render_diff(report, fmt), args.output)
    for failure in report.failures:
        print(f"archmetrics: {failure}", file=sys.stderr)
    return EXIT_GATE if report.failures else EXIT_OK


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        if getattr(args, "jobs", 0) < 0:
            raise UsageError("--jobs must be 0 or more")
        commands = {
            "scan": _scan,
            "diff": _diff,
            "rules": _rules,
            "graph": _graph,
            "cache": _cache,
        }
        return commands[args.command](args)
    except (
        SourceError,
        ConfigError,
        UnknownLanguage,
        UsageError,
        BadPattern,
        GateError,
        RulePackError,
    ) as error:
        print(f"archmetrics: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("archmetrics: interrupted", file=sys.stderr)
        return 130
