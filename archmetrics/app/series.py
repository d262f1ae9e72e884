"""The ``series`` and ``compare`` use cases: stage after stage, and approach beside approach.

A series measures each stage against the one before it (the first against the empty tree, or
against ``root``), as the thesis measured its baseline, first and second stages (p. 111).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from archmetrics.app.diff import run_diff
from archmetrics.app.diff_options import DiffRequest, diff_options
from archmetrics.app.progress import Progress
from archmetrics.reports.model import CompareReport, SeriesReport, Stage
from archmetrics.sources import EMPTY
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.checkout import Checkout, open_checkout


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
    request: SeriesRequest,
    progress: Progress | None = None,
    cache: FactsCache | None = None,
    checkout: Checkout | None = None,
) -> SeriesReport:
    """Each stage against the one before it; ``checkout``: the repository, if the caller
    opened it already."""
    pairs = stage_pairs(request)
    checkout = checkout or open_checkout(request.diff.root)  # once for all stages, as are
    # the options
    options = diff_options(request.diff, checkout.root, checkout)
    stages = []
    for label, base, head in pairs:
        stage = replace(request.diff, base=base, head=head)
        stages.append(Stage(label, run_diff(stage, progress, cache, checkout, options)))
    return SeriesReport(str(request.diff.root), tuple(stages))


def run_compare(
    named: Sequence[tuple[str, SeriesRequest]],
    progress: Progress | None = None,
    cache: FactsCache | None = None,
    checkouts: Mapping[str, Checkout] | None = None,
) -> CompareReport:
    """One series per named repository, side by side; ``checkouts``: the repositories the
    caller opened already, by name."""
    names = [name for name, _ in named]
    if len(set(names)) != len(names):
        raise SeriesError(f"each repository needs its own name: {', '.join(names)}")
    opened = checkouts or {}
    return CompareReport(
        tuple((name, run_series(r, progress, cache, opened.get(name))) for name, r in named)
    )


def parse_named_path(text: str) -> tuple[str, Path]:
    """``NAME=PATH`` as given to ``compare``."""
    name, sep, path = text.partition("=")
    if not sep or not name or not path:
        raise SeriesError(f"{text!r}: expected NAME=PATH, e.g. soa=./wdb-soa")
    return name, Path(path)
