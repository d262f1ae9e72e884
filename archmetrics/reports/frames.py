"""Reports as tables of plain values: a header and rows, ``None`` where a cell does not apply.

The CSV output writes these tables (``None`` as an empty cell), and :mod:`archmetrics.api`
gives the same tables to pandas (``None`` as a missing value), so a notebook and a spreadsheet
see the same rows and columns (docs/api.md).
"""

from __future__ import annotations

from dataclasses import dataclass

from archmetrics.changeset.model import SUMMARY_FIELDS
from archmetrics.reports import coupling_rows
from archmetrics.reports.diff_rows import TREND_FIELDS
from archmetrics.reports.model import (
    LOCATION_COLUMNS,
    CompareReport,
    DiffReport,
    EstimateReport,
    HistoryReport,
    ScanReport,
    SeriesReport,
)

Cell = str | int | float | None


@dataclass(frozen=True, slots=True)
class Table:
    columns: tuple[str, ...]
    rows: list[tuple[Cell, ...]]


SCAN_GROUPINGS = ("file", "function", "element", "link")
_METRICS = ("loc", "sloc", "vg", "s_a", "s_e", "d_a", "d_e")
_NUMERIC_SUMMARY = tuple(f for f in SUMMARY_FIELDS if f != "notes")


def scan_table(report: ScanReport, grouping: str = "file", excluded: bool = False) -> Table:
    """One row per file, function, element or link (``grouping``); by file with ``excluded``
    (the CSV), each file the configuration or ``--exclude`` left out too, with its reason
    in an ``excluded`` column (a DataFrame keeps the measured files alone: numbers stay
    numbers; ``ScanReport.excluded`` has the rest)."""
    if grouping == "function":
        return Table(
            ("path", "language", "function", "line", "loc", "vg"),
            [
                (file.path, file.language, f.qualified_name, f.line, f.loc, f.vg)
                for file in report.files
                for f in file.functions
            ],
        )
    if grouping == "element":
        return Table(
            ("element", "files", *_METRICS),
            [
                (r.element, " ".join(r.files), r.loc, r.sloc, r.vg, r.s_a, r.s_e, r.d_a, r.d_e)
                for r in report.element_rows()
            ],
        )
    if grouping == "link":
        columns = ("element", "where", "link", "rule", "kind", "role", "target", "status")
        rows = coupling_rows.link_rows(report.coupling)  # "" where a static link has no kind
        return Table(columns, [tuple(cell or None for cell in row) for row in rows])
    return _file_table(report, excluded)


def _file_table(report: ScanReport, excluded: bool) -> Table:
    """A row per file; with ``excluded``, a row per excluded file too (no numbers: listed,
    not counted) and the reason in a last column."""
    columns = ("path", "language", "loc", "sloc", "vg", "functions", "warnings")
    rows: list[tuple[Cell, ...]] = [
        (f.path, f.language, f.loc, f.sloc, f.vg, len(f.functions), len(f.warnings))
        for f in report.files
    ]
    if not excluded:
        return Table(columns, rows)
    rows = [(*row, None) for row in rows]
    rows += [(x.path, *(None,) * 6, x.reason) for x in report.excluded]
    return Table((*columns, "excluded"), rows)


def diff_table(report: DiffReport) -> Table:
    """A row per location and the total (``row`` = location: the summary fields), then a row
    per element (``row`` = element: its Γ counts, its metrics before and after), then a row
    per excluded file (``row`` = excluded: its path, and its reason as the note)."""
    sides = tuple(f"{side}_{m}" for side in ("pre", "post") for m in _METRICS)
    columns = ("row", "name", "location", "status", *_NUMERIC_SUMMARY, *sides, "files", "notes")
    no_sides: tuple[Cell, ...] = (None,) * len(sides)
    rows: list[tuple[Cell, ...]] = []
    for name, summary in report.summaries().items():
        values = tuple(getattr(summary, f) for f in _NUMERIC_SUMMARY)
        notes = " | ".join(summary.notes) or None
        rows.append(("location", name, name, None, *values, *no_sides, None, notes))
    for e in report.change.elements:
        counts = {
            "added": e.added,
            "removed": e.removed,
            "modified": e.modified,
            "changes": e.added + e.removed + e.modified,
        }
        values = tuple(counts.get(f) for f in _NUMERIC_SUMMARY)
        metrics = tuple(getattr(m, f) if m else None for m in (e.pre, e.post) for f in _METRICS)
        rows.append(
            ("element", e.element, e.location.value, e.status.value, *values, *metrics,
             " ".join(e.files), None)
        )  # fmt: skip
    none = (None,) * (len(_NUMERIC_SUMMARY) + len(sides))
    for x in report.change.excluded:  # counted nowhere, listed: the reason is its note
        rows.append(("excluded", x.path, None, None, *none, x.path, x.reason))
    return Table(columns, rows)


def trend_table(report: CompareReport) -> Table:
    """A row per approach, stage and location: the trend fields (thesis figures 7-2 to 7-6)."""
    rows: list[tuple[Cell, ...]] = []
    for approach, series in report.series:
        rows.extend(_trend_rows(approach, series))
    return Table(("approach", "stage", "location", *(f for f, _ in TREND_FIELDS)), rows)


def _trend_rows(approach: str, series: SeriesReport) -> list[tuple[Cell, ...]]:
    rows: list[tuple[Cell, ...]] = []
    for stage in series.stages:
        summaries = stage.report.summaries()
        for location in LOCATION_COLUMNS:
            summary = summaries[location]
            values = tuple(getattr(summary, f) for f, _ in TREND_FIELDS)
            rows.append((approach, stage.label, location, *values))
    return rows


def history_table(report: HistoryReport) -> Table:
    """A row per commit and location: the commit, its date (ISO 8601, UTC) and subject,
    then the trend fields, Γ_A, Γ_R, Γ_M and Vg_post."""
    from archmetrics.reports.history_rows import TABLE_FIELDS, long_rows

    return Table(("commit", "date", "subject", "location", *TABLE_FIELDS), long_rows(report))


def estimate_table(report: EstimateReport) -> Table:
    """:func:`diff_table` of every architecture's stages, with ``architecture`` and ``stage``
    columns in front (an estimate: planned or sketched figures)."""
    columns: tuple[str, ...] = ()
    rows: list[tuple[Cell, ...]] = []
    for architecture in report.architectures:
        for stage in architecture.series.stages:
            table = diff_table(stage.report)
            columns = ("architecture", "stage", *table.columns)
            rows += [(architecture.name, stage.label, *row) for row in table.rows]
    return Table(columns, rows)


def accuracy_table(report: EstimateReport) -> Table:
    """--actual: a row per architecture, location or element, and figure: estimated,
    measured, error (estimated − measured) and relative error (error / |measured|)."""
    rows: list[tuple[Cell, ...]] = []
    for name, accuracy in report.accuracy:
        for scope, places in (("location", accuracy.locations), ("element", accuracy.elements)):
            for place in places:
                for f in place.figures:
                    rows.append(
                        (name, scope, place.name, place.location, f.figure, f.estimated,
                         f.actual, f.error, f.relative)
                    )  # fmt: skip
    columns = ("architecture", "row", "name", "location", "figure", "estimated", "actual")
    return Table((*columns, "error", "relative"), rows)
