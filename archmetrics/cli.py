"""The ``archmetrics`` command line: flags become a request, one use case runs, a report prints.

Exit status: 0 measured (and every gate holds), 1 a gate failed, 2 could not measure (bad usage,
unknown revision, bad configuration) with a one-line error and no traceback.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

from archmetrics import __version__
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.app.scan import ScanRequest, run_scan
from archmetrics.config import ConfigError, Settings, load_settings
from archmetrics.parsers import UnknownLanguage
from archmetrics.reports.formats import Grouping, OutputFormat, render_scan
from archmetrics.sources import SourceError

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


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="archmetrics", description=__doc__.split("\n")[0])
    parser.add_argument("--version", action="version", version=f"archmetrics {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    scan = commands.add_parser("scan", help="λ, SLOC and v_g per file and function")
    scan.add_argument("paths", nargs="*", type=Path, metavar="PATH", help="files or folders")
    scan.add_argument("--rev", help="measure this git revision instead of the files on disk")
    scan.add_argument("--by", choices=[g.value for g in Grouping], default="file")
    scan.add_argument("--sample", action="store_true", help="scan the sample shipped with archmetrics")
    _add_output(scan, [f.value for f in OutputFormat])
    return parser


def _settings_for(path: Path) -> Settings:
    from archmetrics.sources import git

    folder = path if path.is_dir() else path.parent
    if git.is_repository(folder):
        return load_settings(git.toplevel(git.open_repository(folder)))
    return load_settings(folder)


def _emit(text: str, output: Path | None) -> None:
    if output is None:
        sys.stdout.write(text)
        return
    try:
        output.write_text(text, encoding="utf-8")
    except OSError as error:
        raise UsageError(f"{output}: cannot write: {error.strerror}") from error


def _scan(args: argparse.Namespace) -> int:
    paths: tuple[Path, ...] = tuple(args.paths)
    if args.sample:
        if paths or args.rev:
            raise UsageError("--sample takes no PATH and no --rev")
        paths = (sample_path(),)
    settings = _settings_for(paths[0] if paths else Path.cwd())
    fmt = OutputFormat(args.format)
    request = ScanRequest(paths=paths, rev=args.rev, settings=settings, jobs=args.jobs)
    report = run_scan(request, _progress(fmt, args.quiet))
    _emit(render_scan(report, fmt, Grouping(args.by)), args.output)
    return EXIT_OK


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        if args.jobs < 0:
            raise UsageError("--jobs must be 0 or more")
        return {"scan": _scan}[args.command](args)
    except (SourceError, ConfigError, UnknownLanguage, UsageError) as error:
        print(f"archmetrics: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("archmetrics: interrupted", file=sys.stderr)
        return 130
