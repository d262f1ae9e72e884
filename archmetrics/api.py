"""archmetrics for notebooks: scans, diffs, series, comparisons, estimates and histories as
DataFrames.

Each function measures as the command of the same name does (the repository's configuration,
the facts cache, the parser processes) and returns one row per function, file, element,
link, location or stage: the rows and columns of the command's ``--format csv`` (both come
from :mod:`archmetrics.reports.frames`), with numbers as numbers and a missing value where a
cell does not apply. docs/api.md shows a notebook that plots E across stages.

    >>> from archmetrics import api
    >>> api.scan("src", by="function").sort_values("vg").tail()
    >>> api.series("wdb-soa", ["baseline", "first", "second"]).query("location == 'new'")
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from archmetrics.app.collect import open_cache
from archmetrics.app.diff import run_diff
from archmetrics.app.diff_options import DiffRequest
from archmetrics.app.estimate import EstimateRequest, run_estimate
from archmetrics.app.history import HistoryRequest, run_history
from archmetrics.app.scan import ScanRequest, run_scan
from archmetrics.app.series import SeriesRequest, run_compare, run_series
from archmetrics.app.settings import settings_for
from archmetrics.config import Settings
from archmetrics.reports.frames import (
    SCAN_GROUPINGS,
    Table,
    accuracy_table,
    diff_table,
    estimate_table,
    history_table,
    scan_table,
    trend_table,
)
from archmetrics.reports.model import CompareReport
from archmetrics.sources import EMPTY
from archmetrics.sources.cache import FactsCache, choose_path
from archmetrics.sources.checkout import open_checkout
from archmetrics.sources.githistory import Range

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["compare", "diff", "estimate", "history", "scan", "series"]


def scan(
    path: str | Path = ".",
    *,
    rev: str | None = None,
    by: str = "file",
    exclude: Sequence[str] = (),
    cache: bool = True,
    jobs: int = 0,
) -> pd.DataFrame:
    """One row per file (``by="file"``), function, element or link of the files under
    ``path`` (at git revision ``rev``, or as on disk), as ``archmetrics scan --by BY``."""
    if by not in SCAN_GROUPINGS:
        raise ValueError(f"by={by!r}: expected one of {', '.join(SCAN_GROUPINGS)}")
    path = Path(path)
    settings = settings_for(path, exclude)
    with _cache(settings, cache) as facts:
        report = run_scan(ScanRequest((path,), rev, settings, jobs), cache=facts)
    return _frame(scan_table(report, by))


def diff(
    repo: str | Path = ".",
    base: str = "HEAD",
    head: str = "WORKTREE",
    *,
    new: Sequence[str] = (),
    framework: Sequence[str] = (),
    exclude: Sequence[str] = (),
    cache: bool = True,
    jobs: int = 0,
) -> pd.DataFrame:
    """The chapter-6 metrics of the change from ``base`` to ``head``, as ``archmetrics diff``:
    a row per location and the total (``row == "location"``), then a row per element."""
    request = _diff_request(Path(repo), new, framework, exclude, jobs, base, head)
    with _cache(request.settings, cache) as facts:
        report = run_diff(request, cache=facts)
    return _frame(diff_table(report))


def series(
    repo: str | Path,
    revisions: Sequence[str],
    labels: Sequence[str] = (),
    *,
    root: str = EMPTY,
    new: Sequence[str] = (),
    framework: Sequence[str] = (),
    exclude: Sequence[str] = (),
    cache: bool = True,
    jobs: int = 0,
) -> pd.DataFrame:
    """Each stage measured against the one before (the first against ``root``), as
    ``archmetrics series``: a row per stage and location with the trend fields."""
    request = SeriesRequest(
        _diff_request(Path(repo), new, framework, exclude, jobs),
        tuple(revisions),
        tuple(labels),
        root,
    )
    with _cache(request.diff.settings, cache) as facts:
        report = run_series(request, cache=facts)
    return _frame(trend_table(CompareReport((("", report),))))


def compare(
    repos: Mapping[str, str | Path],
    revisions: Sequence[str] = (),
    labels: Sequence[str] = (),
    *,
    root: str = EMPTY,
    new: Sequence[str] = (),
    framework: Sequence[str] = (),
    cache: bool = True,
    jobs: int = 0,
) -> pd.DataFrame:
    """The same series for several repositories side by side, as ``archmetrics compare``:
    a row per approach (the name given), stage and location. Without ``revisions``, each
    repository's tags in history order."""
    named = []
    for name, path in repos.items():
        stages = tuple(revisions) or open_checkout(Path(path)).tags()
        request = _diff_request(Path(path), new, framework, (), jobs)
        named.append((name, SeriesRequest(request, stages, tuple(labels), root)))
    if not named:
        raise ValueError("compare needs at least one repository")
    with _cache(named[0][1].diff.settings, cache) as facts:
        report = run_compare(named, cache=facts)
    return _frame(trend_table(report))


def estimate(
    plan: str | Path,
    repo: str | Path = ".",
    base: str = "HEAD",
    *,
    actual: str | None = None,
    stage: str | None = None,
    new: Sequence[str] = (),
    framework: Sequence[str] = (),
    exclude: Sequence[str] = (),
    cache: bool = True,
    jobs: int = 0,
) -> pd.DataFrame:
    """Each architecture of ``plan`` estimated against ``base``, as ``archmetrics estimate``:
    the diff's rows per architecture and stage. With ``actual`` (a revision), each figure's
    error against the measured ``base..actual`` instead, as ``estimate --actual``."""
    diff = _diff_request(Path(repo), new, framework, exclude, jobs, base)
    request = EstimateRequest(Path(plan), diff, actual, stage)
    with _cache(diff.settings, cache) as facts:
        report = run_estimate(request, cache=facts)
    return _frame(estimate_table(report) if actual is None else accuracy_table(report))


def history(
    repo: str | Path = ".",
    revisions: str = "HEAD",
    *,
    first_parent: bool = True,
    merges: bool = False,
    since: str | None = None,
    until: str | None = None,
    max_count: int | None = None,
    new: Sequence[str] = (),
    framework: Sequence[str] = (),
    exclude: Sequence[str] = (),
    scheduler: str | None = None,
    workers: int | None = None,
    jobs: int = 0,
) -> pd.DataFrame:
    """Every commit of ``revisions`` (a range as git log takes it) against its first parent,
    as ``archmetrics history``: a row per commit and location, with its date (ISO 8601, UTC)
    and subject, the trend fields, Γ_A, Γ_R, Γ_M and Vg after it. Steps are kept in the
    facts cache (a history always uses one: a temporary one when the configuration turns
    it off); ``scheduler`` or ``workers`` run it on a Dask cluster."""
    from tempfile import TemporaryDirectory

    request = HistoryRequest(
        _diff_request(Path(repo), new, framework, exclude, jobs),
        Range(revisions, first_parent, merges, since, until, max_count),
        scheduler,
        workers,
    )
    settings = request.diff.settings
    with _cache(settings, True) as facts:
        if facts is not None:
            report = run_history(request, cache=facts)
        else:
            with TemporaryDirectory() as folder, open_cache(Path(folder) / "f", settings) as own:
                report = run_history(request, cache=own)
    return _frame(history_table(report))


def _frame(table: Table) -> pd.DataFrame:
    try:
        import pandas as pd  # 0.3 s to import: only when a frame is asked for
    except ModuleNotFoundError as error:
        raise ModuleNotFoundError(
            "archmetrics.api returns pandas DataFrames, and pandas is not installed:"
            " pip install 'archmetrics[api]'",
            name="pandas",
        ) from error

    return pd.DataFrame.from_records(table.rows, columns=list(table.columns))


def _diff_request(
    repo: Path,
    new: Sequence[str],
    framework: Sequence[str],
    exclude: Sequence[str],
    jobs: int,
    base: str = "",
    head: str = "",
) -> DiffRequest:
    settings = settings_for(repo, exclude)
    return DiffRequest(repo, base, head, settings, tuple(new), tuple(framework), jobs=jobs)


@contextmanager
def _cache(settings: Settings, use: bool) -> Iterator[FactsCache | None]:
    """The facts cache the configuration names (the command's default), or none."""
    if not (use and settings.cache):
        yield None
        return
    with open_cache(choose_path(None, settings.cache_path, settings.source), settings) as facts:
        yield facts
