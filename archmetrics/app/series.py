"""The ``series`` and ``compare`` use cases: stage after stage, and approach beside approach.

A series measures each stage against the one before it (the first against the empty tree, or
against ``root``), as the thesis measured its baseline, first and second stages (p. 111).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from archmetrics.app.diff import DiffRequest, run_diff
from archmetrics.app.progress import Progress
from archmetrics.reports.model import CompareReport, SeriesReport, Stage
from archmetrics.sources import EMPTY
from archmetrics.sources.cache import FactsCache


class SeriesError(ValueError):
    """Revisions and labels that do not make a series; the message says why."""


@dataclass(frozen=True, slots=True)
class SeriesRequest:
    """``revisions`` in order; ``labels`` name the stages (default: the revisions)."""

    diff: DiffRequest  # root, settings, locations, gates, jobs; base/head are set per stage
    revisions: tuple[str, ...]
    labels: tuple[str, ...] = ()
    root_revision: str = EMPTY


def stage_pairs(request: SeriesRequest) -> list[tuple[str, str, str]]:
    """(label, base, head) per stage."""
    if not request.revisions:
        raise SeriesError("a series needs at least one revision")
    labels = request.labels or request.revisions
    if len(labels) != len(request.revisions):
        raise SeriesError(
            f"{len(labels)} labels for {len(request.revisions)} revisions: give one label a stage"
        )
    bases = (request.root_revision, *request.revisions[:-1])
    return list(zip(labels, bases, request.revisions, strict=True))


def run_series(
    request: SeriesRequest, progress: Progress | None = None, cache: FactsCache | None = None
) -> SeriesReport:
    stages = []
    for label, base, head in stage_pairs(request):
        report = run_diff(replace(request.diff, base=base, head=head), progress, cache)
        stages.append(Stage(label, report))
    return SeriesReport(str(request.diff.root), tuple(stages))


def run_compare(
    named: Sequence[tuple[str, SeriesRequest]],
    progress: Progress | None = None,
    cache: FactsCache | None = None,
) -> CompareReport:
    """One series per named repository, side by side."""
    names = [name for name, _ in named]
    if len(set(names)) != len(names):
        raise SeriesError(f"each repository needs its own name: {', '.join(names)}")
    return CompareReport(tuple((name, run_series(r, progress, cache)) for name, r in named))


def parse_named_path(text: str) -> tuple[str, Path]:
    """``NAME=PATH`` as given to ``compare``."""
    name, sep, path = text.partition("=")
    if not sep or not name or not path:
        raise SeriesError(f"{text!r}: expected NAME=PATH, e.g. soa=./wdb-soa")
    return name, Path(path)
