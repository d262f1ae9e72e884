"""The ``history`` command: every commit of a branch measured against its first parent."""

from __future__ import annotations

import argparse
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from archmetrics.app.collect import open_cache
from archmetrics.app.history import HistoryRequest, run_history
from archmetrics.cli.common import UsageError, emit, facts_cache, gate_status, shown_progress
from archmetrics.cli.measure import check_chart, diff_request
from archmetrics.config import Settings
from archmetrics.reports.formats import OutputFormat
from archmetrics.reports.history_report import HistoryFormat, View, render_history
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.checkout import open_checkout
from archmetrics.sources.githistory import Range
from archmetrics.sources.snapshot import WORKTREE


@contextmanager
def _history_cache(args: argparse.Namespace, settings: Settings) -> Iterator[FactsCache]:
    """The facts cache, or with --no-cache one of this run's own, deleted at its end: a
    history parses each file version once and reads it back at every commit that holds it."""
    with facts_cache(args, settings) as cache:
        if cache is not None:
            yield cache
            return
    with (
        tempfile.TemporaryDirectory(prefix="archmetrics-history-") as folder,
        open_cache(Path(folder) / "facts.sqlite3", settings) as own,
    ):
        yield own


def history_range(args: argparse.Namespace) -> Range:
    if args.max_count is not None and args.max_count < 1:
        raise UsageError("--max-count needs a number of commits of at least 1")
    return Range(args.range, args.first_parent, args.merges, args.since, args.until,
                 args.max_count)  # fmt: skip


def history_command(args: argparse.Namespace) -> int:
    check_chart(args)
    if args.top < 0:
        raise UsageError("--top needs a number of at least 0")
    fmt = HistoryFormat(args.format)
    checkout = open_checkout(args.repo)
    if args.workers is not None and args.workers < 1:
        raise UsageError("--workers needs a number of at least 1")
    request = HistoryRequest(
        # the configuration on disk: the range's commits each have their own, and one
        # run measures every commit by one set of rules
        diff_request(args, checkout, config_base=WORKTREE, config_head=WORKTREE),
        history_range(args),
        args.scheduler,
        args.workers,
    )
    shown = OutputFormat.TABLE if fmt is HistoryFormat.TABLE else OutputFormat.JSON
    with (
        _history_cache(args, request.diff.settings) as cache,
        shown_progress(shown, args.quiet) as progress,
    ):
        report = run_history(request, progress, cache, checkout)
        progress.phase("writing the report")
        text = render_history(report, fmt, View(args.top, args.element))
    emit(text, args.output)
    if args.chart is not None:
        from archmetrics.reports.charts_history import render_history_chart

        chart = render_history_chart(report, args.chart.suffix.lower().lstrip("."))
        try:
            args.chart.write_bytes(chart)
        except OSError as error:
            raise UsageError(f"{args.chart}: cannot write: {error.strerror}") from error
    return gate_status(report.failures, args)
