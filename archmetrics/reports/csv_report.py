"""CSV: the tables of reports/frames.py (one row per file, function, element, link, location
or stage), for spreadsheets; an empty cell where a value does not apply."""

from __future__ import annotations

import csv
import io

from archmetrics.reports.frames import (
    Table,
    accuracy_table,
    diff_table,
    estimate_table,
    scan_table,
    trend_table,
)
from archmetrics.reports.model import (
    CompareReport,
    DiffReport,
    EstimateReport,
    ScanReport,
    SeriesReport,
)


def write_csv(table: Table) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(table.columns)
    writer.writerows(("" if cell is None else cell for cell in row) for row in table.rows)
    return out.getvalue()


def render_scan(report: ScanReport, grouping: str) -> str:
    """One row per file, function, element or link (``grouping``); by file, the excluded
    files too (each with its reason in the last column)."""
    return write_csv(scan_table(report, grouping, excluded=True))


def render_diff(report: DiffReport) -> str:
    """One table: a row per location and the total (summary fields), then a row per element
    (its pre/post metrics and Γ counts); cells that do not apply are empty."""
    return write_csv(diff_table(report))


def render_series(report: SeriesReport) -> str:
    """A row per stage and location: the trend fields (raw numbers)."""
    return render_compare(CompareReport((("", report),)))


def render_compare(report: CompareReport) -> str:
    return write_csv(trend_table(report))


def render_estimate(report: EstimateReport) -> str:
    """The diff's rows (a row per location, then per element) for every architecture and
    stage, named in the first two columns; with --actual, each figure's error instead."""
    return write_csv(estimate_table(report) if report.actual is None else accuracy_table(report))
