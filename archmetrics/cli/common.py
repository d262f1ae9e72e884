"""What every command shares: errors, progress, settings, the cache, output."""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any, NoReturn

from archmetrics.app import settings as app_settings
from archmetrics.app.collect import open_cache
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.changeset.gates import GateFailure
from archmetrics.complexity.thresholds import ThresholdFailure, worst_first
from archmetrics.config import Settings
from archmetrics.globs import BadPattern
from archmetrics.reports.formats import OutputFormat
from archmetrics.reports.model import EstimateFailure
from archmetrics.reports.printable import one_line, shown_lines
from archmetrics.reports.table_report import SHOWN_FAILURES
from archmetrics.sources.cache import FactsCache, choose_path
from archmetrics.sources.checkout import Checkout
from archmetrics.sources.confine import confined, write_confined

EXIT_OK, EXIT_GATE, EXIT_USAGE = 0, 1, 2


class UsageError(Exception):
    """Bad usage found after parsing (a missing file, a bad value)."""


class HelpFormatter(argparse.HelpFormatter):
    """argparse's, except that a path in the text (the installed docs, in site-packages) is
    never broken at a hyphen or inside itself."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        import textwrap

        return textwrap.fill(
            " ".join(text.split()), width, initial_indent=indent, subsequent_indent=indent,
            break_on_hyphens=False, break_long_words=False,
        )  # fmt: skip


class Parser(argparse.ArgumentParser):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see --help)\n")


def _rate_column() -> Any:
    """A progress column with how many steps a second are done (files parsed, commits
    measured), once rich has seen enough to say."""
    from rich.progress import ProgressColumn, Task
    from rich.text import Text

    class Rate(ProgressColumn):
        def render(self, task: Task) -> Text:
            speed = task.speed
            return Text(f"{speed:.1f}/s" if speed else "", style="progress.data.speed")

    return Rate()


class RichProgress:
    """A rich progress bar on stderr, for runs over many files in a terminal."""

    def __init__(self) -> None:
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TimeRemainingColumn,
        )

        self._console = Console(stderr=True)
        self._bar = Progress(
            "[progress.description]{task.description}",
            BarColumn(),
            MofNCompleteColumn(),
            _rate_column(),
            TimeRemainingColumn(),
            console=self._console,
            transient=True,
        )
        self._task: object = None
        self._status: Any = None  # a rich Status: the spinner of a step without a count

    def phase(self, description: str) -> None:
        """A spinner and the step's name, until the next step (a name may hold a tag of
        the repository's: never read as rich markup)."""
        self.stop()
        from rich.markup import escape

        self._status = self._console.status(f"{escape(description)} ...")
        self._status.start()

    def start(self, description: str, total: int) -> None:
        self.stop()
        if total >= 20:
            self._bar.start()
            from rich.markup import escape

            self._task = self._bar.add_task(escape(description), total=total)

    def advance(self, count: int = 1) -> None:
        if self._task is not None:
            self._bar.advance(self._task, count)  # type: ignore[arg-type]

    def stop(self) -> None:
        if self._status is not None:
            self._status.stop()
            self._status = None
        if self._task is not None:
            self._bar.stop()
            self._task = None


def progress_for(fmt: OutputFormat, quiet: bool) -> Progress:
    if quiet or fmt is not OutputFormat.TABLE or not sys.stderr.isatty():
        return NoProgress()
    return RichProgress()


@contextmanager
def shown_progress(fmt: OutputFormat, quiet: bool) -> Iterator[Progress]:
    """The run's progress, its last step ended however the run ends (an error included)."""
    progress = progress_for(fmt, quiet)
    try:
        yield progress
    finally:
        progress.stop()


def sample_path() -> Path:
    """The small sample tree shipped inside the package (the default main job's input)."""
    return Path(__file__).resolve().parent.parent / "data" / "sample"


def settings_for(path: Path, args: argparse.Namespace | None = None) -> Settings:
    """The configuration of the repository (or folder) holding ``path``, with the command
    line's ``--exclude`` globs after the configured ones (each checked now, exit 2 if bad)."""
    return _with_excludes(app_settings.settings_for, path, args)


def settings_at(root: Path, args: argparse.Namespace | None = None) -> Settings:
    """As :func:`settings_for`, of the repository whose top the command has opened."""
    return _with_excludes(app_settings.settings_at, root, args)


def settings_of(checkout: Checkout, spec: str | None, args: argparse.Namespace) -> Settings:
    """As :func:`settings_for`, of the snapshot ``spec`` names (a revision's own
    configuration, read from its blobs: app.settings.settings_of)."""

    def load(_: Path, exclude: tuple[str, ...], raised: bool) -> Settings:
        return app_settings.settings_of(checkout, spec, exclude, raised)

    return _with_excludes(load, checkout.root, args)


def settings_from_file(path: Path, args: argparse.Namespace) -> Settings:
    """As :func:`settings_for`, of the runner's file ``path`` (``--config-from FILE``)."""
    return _with_excludes(app_settings.settings_from_file, path, args)


def _with_excludes(
    load: Callable[[Path, tuple[str, ...], bool], Settings],
    path: Path,
    args: argparse.Namespace | None,
) -> Settings:
    """The settings ``load`` reads, with the command line's --exclude globs and, with
    --allow-raised-limits, the configuration's limits above the defaults; each limit put
    back to its default is a warning."""
    try:
        raised = bool(getattr(args, "allow_raised_limits", False))
        settings = load(path, tuple(getattr(args, "exclude", None) or ()), raised)
    except BadPattern as error:
        raise UsageError(f"--exclude: {error}") from None
    group = getattr(args, "group", None)
    if group is not None:  # --group over [tool.archmetrics.coupling] group
        coupling = dataclasses.replace(settings.coupling, group=group, per_file=group == "file")
        settings = dataclasses.replace(settings, coupling=coupling)
    for notice in settings.notices:
        warn(notice)
    if args is not None:
        _detail(args, f"configuration: {settings.source}")
    return settings


_READ_PATHS = ("paths", "repo", "plan")  # the arguments naming what a command reads


def check_paths(args: argparse.Namespace) -> None:
    """Every path the command line names for reading (``scan PATH``, ``-C``, ``NAME=PATH``,
    the plan, ``--config-from FILE``), checked before any work: a symbolic link on the way
    that leads out of the repository holding it is a one-line error (sources/confine.py).
    The paths themselves are used as given."""
    named: list[Path] = []
    for attribute in _READ_PATHS:
        value = getattr(args, attribute, None)
        values = value if isinstance(value, list) else [value] if value is not None else []
        named += [Path(v) for v in values]
    named += [Path(text.partition("=")[2]) for text in getattr(args, "repos", None) or []]
    if getattr(args, "config_from", "base") not in ("base", "head"):
        named.append(Path(args.config_from))
    for path in named:
        confined(path)


def emit(text: str, output: Path | None) -> None:
    """Write a report to ``output``, or to stdout. A file is UTF-8; stdout is written in its
    own encoding, or as UTF-8 bytes when that encoding (ASCII, cp1252) cannot hold the
    report's Γ, Δ and arrows: a report is never lost to an encoding."""
    if output is None:
        try:
            sys.stdout.write(text)
        except UnicodeEncodeError:
            sys.stdout.flush()
            sys.stdout.buffer.write(text.encode("utf-8", "backslashreplace"))
            sys.stdout.buffer.flush()
        return
    write_output(output, text.encode("utf-8", "backslashreplace"))


def write_output(output: Path, data: bytes) -> None:
    """``data`` into the file ``output`` (created or replaced; never through a symbolic link
    inside a repository, nor through one on the way leading out of it: sources/confine.py)."""
    try:
        write_confined(output, data)
    except OSError as error:
        raise UsageError(f"{output}: cannot write: {error.strerror or error}") from error


def warn(message: str) -> None:
    """A one-line warning on stderr (control characters from the measured code escaped)."""
    print(f"archmetrics: warning: {one_line(message)}", file=sys.stderr)


def cache_location(args: argparse.Namespace, settings: Settings) -> Path:
    """The cache file: the flag, the environment, the configuration (confined), the default."""
    return choose_path(getattr(args, "cache_path", None), settings.cache_path, settings.source)


@contextmanager
def facts_cache(args: argparse.Namespace, settings: Settings) -> Iterator[FactsCache | None]:
    """The cache the flags and settings ask for (none with --no-cache or cache = false).
    Problems it recovered from are printed as it opens and, if more came up, as it closes."""
    started = time.monotonic()
    if getattr(args, "no_cache", False) or not settings.cache:
        yield None
        _detail(args, f"no facts cache; measured in {time.monotonic() - started:.2f} s")
        return
    with open_cache(cache_location(args, settings), settings) as cache:
        for notice in cache.notices:
            warn(notice)
        shown = len(cache.notices)
        try:
            yield cache
        finally:
            for notice in cache.notices[shown:]:
                warn(notice)
            _detail(
                args,
                f"facts cache {cache.path}: {cache.hits} files' facts served, {cache.misses} "
                f"parsed; measured in {time.monotonic() - started:.2f} s",
            )


def _detail(args: argparse.Namespace, text: str) -> None:
    """A line of detail on stderr with -v (never with -v absent: -q stays quiet)."""
    if getattr(args, "verbose", False):
        print(f"archmetrics: {one_line(text)}", file=sys.stderr)


def gate_status(
    failures: Sequence[GateFailure | ThresholdFailure | EstimateFailure], args: argparse.Namespace
) -> int:  # (worst first: the units past their limits furthest)
    """Exit 1 if a gate failed, else 0. Each failure goes to stderr unless the report itself
    showed it on stdout (a table or Markdown, every report lists its failed gates): a
    failure is printed once, and a report written to a file or as data still names it;
    past the first ``SHOWN_FAILURES`` (a threshold thousands of functions fail), a count."""
    on_stdout = (OutputFormat.TABLE, OutputFormat.MARKDOWN, OutputFormat.WARNINGS)
    shown = args.output is None and args.format in on_stdout
    if not shown:
        more = "... and {count} more failures (the report lists them)"
        units = worst_first(f for f in failures if isinstance(f, ThresholdFailure))
        ordered = [f for f in failures if not isinstance(f, ThresholdFailure)] + list(units)
        for line in shown_lines(ordered, SHOWN_FAILURES, more):
            print(f"archmetrics: {one_line(line)}", file=sys.stderr)
    return EXIT_GATE if failures else EXIT_OK


def split(text: str | None) -> tuple[str, ...]:
    return tuple(part.strip() for part in text.split(",") if part.strip()) if text else ()
