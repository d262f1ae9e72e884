"""Output formats, mapped to renderers with an exhaustiveness check."""

from __future__ import annotations

from collections.abc import Callable
from enum import StrEnum

from archmetrics.reports import csv_report, json_report, markdown_report, table_report
from archmetrics.reports.model import ScanReport


class OutputFormat(StrEnum):
    TABLE = "table"
    JSON = "json"
    MARKDOWN = "markdown"
    CSV = "csv"


class Grouping(StrEnum):
    FILE = "file"
    FUNCTION = "function"


ScanRenderer = Callable[[ScanReport, Grouping], str]

_SCAN: dict[OutputFormat, ScanRenderer] = {
    OutputFormat.TABLE: lambda r, g: table_report.render_scan(r, g == Grouping.FUNCTION),
    OutputFormat.JSON: lambda r, g: json_report.render_scan(r),
    OutputFormat.MARKDOWN: lambda r, g: markdown_report.render_scan(r, g == Grouping.FUNCTION),
    OutputFormat.CSV: lambda r, g: csv_report.render_scan(r, g == Grouping.FUNCTION),
}
assert set(_SCAN) == set(OutputFormat), "every output format needs a scan renderer"


def render_scan(report: ScanReport, fmt: OutputFormat, grouping: Grouping) -> str:
    return _SCAN[fmt](report, grouping)
