"""CSV: one row per file or per function, for spreadsheets and pandas."""

from __future__ import annotations

import csv
import io
from typing import Any

from archmetrics.changeset.model import SUMMARY_FIELDS
from archmetrics.reports import coupling_rows
from archmetrics.reports.diff_rows import TREND_FIELDS
from archmetrics.reports.model import (
    LOCATION_COLUMNS,
    CompareReport,
    DiffReport,
    ScanReport,
    SeriesReport,
)


def render_scan(report: ScanReport, grouping: str) -> str:
    """One row per file, function, element or link (``grouping``)."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    if grouping == "function":
        writer.writerow(["path", "language", "function", "line", "loc", "vg"])
        for file in report.files:
            for f in file.functions:
                writer.writerow([file.path, file.language, f.qualified_name, f.line, f.loc, f.vg])
    elif grouping == "element":
        writer.writerow(["element", "files", "loc", "sloc", "vg", "s_a", "s_e", "d_a", "d_e"])
        writer.writerows(coupling_rows.element_rows(report))
    elif grouping == "link":
        writer.writerow(["element", "where", "link", "rule", "kind", "role", "target", "status"])
        writer.writerows(coupling_rows.link_rows(report.coupling))
    else:
        writer.writerow(["path", "language", "loc", "sloc", "vg", "functions", "warnings"])
        for file in report.files:
            writer.writerow(
                [
                    file.path,
                    file.language,
                    file.loc,
                    file.sloc,
                    file.vg,
                    len(file.functions),
                    len(file.warnings),
                ]
            )
    return out.getvalue()


def render_diff(report: DiffReport) -> str:
    """One table: a row per location and the total (summary fields), then a row per element
    (its pre/post metrics and Γ counts); cells that do not apply are empty."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    fields = [f for f in SUMMARY_FIELDS if f != "notes"]
    metric = ("loc", "sloc", "vg", "s_a", "s_e", "d_a", "d_e")
    element_fields = [f"{side}_{m}" for side in ("pre", "post") for m in metric]
    writer.writerow(
        ["row", "name", "location", "status", *fields, *element_fields, "files", "notes"]
    )
    blank_elements = [""] * len(element_fields)
    for name, summary in report.summaries().items():
        values = ["" if getattr(summary, f) is None else getattr(summary, f) for f in fields]
        notes = " | ".join(summary.notes)
        writer.writerow(["location", name, name, "", *values, *blank_elements, "", notes])
    for e in report.change.elements:
        counts = {
            "added": e.added,
            "removed": e.removed,
            "modified": e.modified,
            "changes": e.added + e.removed + e.modified,
        }
        values = [counts.get(f, "") for f in fields]
        sides = [getattr(m, f) if m else "" for m in (e.pre, e.post) for f in metric]
        writer.writerow(
            [
                "element",
                e.element,
                e.location.value,
                e.status.value,
                *values,
                *sides,
                " ".join(e.files),
                "",
            ]
        )
    return out.getvalue()


def _trend(writer: Any, approach: str, series: SeriesReport) -> None:
    for stage in series.stages:
        summaries = stage.report.summaries()
        for location in LOCATION_COLUMNS:
            summary = summaries[location]
            values = [getattr(summary, f) for f, _ in TREND_FIELDS]
            writer.writerow(
                [approach, stage.label, location, *("" if v is None else v for v in values)]
            )


def render_series(report: SeriesReport) -> str:
    """A row per stage and location: the trend fields (raw numbers)."""
    return render_compare(CompareReport((("", report),)))


def render_compare(report: CompareReport) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["approach", "stage", "location", *(f for f, _ in TREND_FIELDS)])
    for name, series in report.series:
        _trend(writer, name, series)
    return out.getvalue()
