"""Charts of a series or a comparison of approaches: the thesis's figures, as PNG or SVG bytes.

Pure functions: a report in, bytes out (matplotlib's Agg canvas, no pyplot, no files). Each kind
reproduces the organisation of a family of figures in Hestand (2011); see ``THESIS_FIGURES``.
Undefined values are drawn as gaps marked "n/a" and footnoted, never as 0; values that rest on
a convention (λ̂ undefined at the baseline, E = 0 by eq. 6.38, ...) carry a mark and a footnote.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import PurePath

from archmetrics.reports.charts_data import (
    COST,
    COUPLING,
    SCALED_CHANGES,
    SCALED_COMPLEXITY,
    TOTAL,
    Scope,
)
from archmetrics.reports.charts_layout import Chart, by_location, coupling, totals
from archmetrics.reports.model import CompareReport, SeriesReport

FORMATS = ("png", "svg")

# kind -> its chart of a comparison; the summary kinds add up the scope's locations
_KINDS: dict[str, Callable[[CompareReport, Scope], Chart]] = {
    "coupling": lambda r, _: coupling(r, COUPLING),
    "scaled_changes": lambda r, _: by_location(r, SCALED_CHANGES),
    "scaled_complexity": lambda r, _: by_location(r, SCALED_COMPLEXITY),
    "cost": lambda r, _: by_location(r, COST),
    "coupling_total": lambda r, s: totals(r, COUPLING, "Summary of coupling changes", s),
    "scaled_changes_total": lambda r, s: totals(
        r, (SCALED_CHANGES,), "Code volume change across stages", s
    ),
    "scaled_complexity_total": lambda r, s: totals(
        r, (SCALED_COMPLEXITY,), "Complexity change across stages", s
    ),
    "cost_total": lambda r, s: totals(r, (COST,), "Complexity change cost across stages", s),
}

# kind -> the thesis figures whose organisation it reproduces
THESIS_FIGURES: dict[str, str] = {
    "coupling": "7.1-7.3, 9.1-9.3 (coupling by location, one figure per approach)",
    "scaled_changes": "7.4, 9.4; 12.1 for one approach (Γ' by location, per approach)",
    "scaled_complexity": "7.5, 9.5; 12.2 for one approach (ΔVg' by location, per approach)",
    "cost": "7.6, 9.6; 12.3 for one approach (E by location, per approach)",
    "coupling_total": "8.1, 10.1 (summary of coupling changes per approach)",
    "scaled_changes_total": "8.2, 10.2, 12.4 (code volume change across stages)",
    "scaled_complexity_total": "8.3, 10.3, 12.5 (complexity change across stages)",
    "cost_total": "8.4, 10.4, 12.6 (complexity change cost across stages)",
}
assert set(THESIS_FIGURES) == set(_KINDS), "every chart kind names its thesis figures"


class ChartError(ValueError):
    """A chart that cannot be drawn: unknown kind or format, or nothing to draw."""


def chart_kinds() -> tuple[str, ...]:
    """The kinds ``render_*_chart`` accept, in the thesis's order within each chapter."""
    return tuple(_KINDS)


def chart_of(report: CompareReport, kind: str, scope: Scope = TOTAL) -> Chart:
    """The pure description of a chart (what ``render_compare_chart`` draws); the ``*_total``
    kinds add up the ``scope``'s locations (the thesis's total by default)."""
    if kind not in _KINDS:
        raise ChartError(f"unknown chart kind {kind!r}: expected one of {', '.join(_KINDS)}")
    if not report.series or not any(s.stages for _, s in report.series):
        raise ChartError("nothing to chart: the report has no stages")
    return _KINDS[kind](report, scope)


def render_compare_chart(
    report: CompareReport, kind: str, fmt: str = "png", scope: Scope = TOTAL
) -> bytes:
    """One chart of several approaches side by side, as PNG or SVG bytes."""
    if fmt not in FORMATS:
        raise ChartError(f"unknown chart format {fmt!r}: expected one of {', '.join(FORMATS)}")
    from archmetrics.reports import charts_draw  # matplotlib: imported only to draw

    return charts_draw.render(chart_of(report, kind, scope), fmt)


def series_name(report: SeriesReport) -> str:
    """The name a lone series is charted under: its repository's folder name."""
    return PurePath(report.repo).name or report.repo or "series"


def render_series_chart(report: SeriesReport, kind: str, fmt: str = "png") -> bytes:
    """One chart of one series: a comparison of one approach."""
    return render_compare_chart(CompareReport(((series_name(report), report),)), kind, fmt)


def render_all(report: CompareReport, fmt: str = "png", scope: Scope = TOTAL) -> dict[str, bytes]:
    """Every kind of chart of the study, keyed by file stem (the kind's name); the summary
    kinds over ``scope``."""
    return {kind: render_compare_chart(report, kind, fmt, scope) for kind in _KINDS}


EXTRA = "pip install 'archmetrics[api]'"


def charts_missing() -> str | None:
    """Why no chart can be drawn in this installation (matplotlib, the ``api`` extra, is
    not installed), or None when charts can be drawn."""
    from importlib.util import find_spec

    try:
        found = find_spec("matplotlib")
    except ValueError:  # a module entry of None: blocked, as good as missing
        found = None
    if found is None:
        return f"charts need matplotlib, which is not installed: {EXTRA}"
    return None
