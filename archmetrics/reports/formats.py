"""Output formats, mapped to renderers with an exhaustiveness check."""

from __future__ import annotations

from collections.abc import Callable
from enum import StrEnum

from archmetrics.reports import csv_report, json_report, markdown_report, table_report
from archmetrics.reports.model import DiffReport, ScanReport


class OutputFormat(StrEnum):
    TABLE = "table"
    JSON = "json"
    MARKDOWN = "markdown"
    CSV = "csv"


class Grouping(StrEnum):
    """What one row of a scan report is (JSON always holds all of them)."""

    FILE = "file"
    FUNCTION = "function"
    ELEMENT = "element"
    LINK = "link"


ScanRenderer = Callable[[ScanReport, str], str]

_SCAN: dict[OutputFormat, ScanRenderer] = {
    OutputFormat.TABLE: table_report.render_scan,
    OutputFormat.JSON: lambda report, grouping: json_report.render_scan(report),
    OutputFormat.MARKDOWN: markdown_report.render_scan,
    OutputFormat.CSV: csv_report.render_scan,
}
assert set(_SCAN) == set(OutputFormat), "every output format needs a scan renderer"


def render_scan(report: ScanReport, fmt: OutputFormat, grouping: Grouping) -> str:
    return _SCAN[fmt](report, grouping.value)


_DIFF: dict[OutputFormat, Callable[[DiffReport], str]] = {
    OutputFormat.TABLE: table_report.render_diff,
    OutputFormat.JSON: json_report.render_diff,
    OutputFormat.MARKDOWN: markdown_report.render_diff,
    OutputFormat.CSV: csv_report.render_diff,
}
assert set(_DIFF) == set(OutputFormat), "every output format needs a diff renderer"


def render_diff(report: DiffReport, fmt: OutputFormat) -> str:
    return _DIFF[fmt](report)
