"""Output formats, mapped to renderers with an exhaustiveness check."""

from __future__ import annotations

from collections.abc import Callable
from enum import StrEnum

from archmetrics.reports import (
    codeclimate_report,
    csv_report,
    json_report,
    markdown_report,
    sarif_report,
    table_report,
    warnings_report,
)
from archmetrics.reports.model import (
    CompareReport,
    DiffReport,
    EstimateReport,
    ScanReport,
    SeriesReport,
)
from archmetrics.reports.printable import printable


class OutputFormat(StrEnum):
    TABLE = "table"
    JSON = "json"
    MARKDOWN = "markdown"
    CSV = "csv"
    CODECLIMATE = "codeclimate"  # GitLab Code Quality: failed gates and thresholds as issues
    SARIF = "sarif"  # GitHub code scanning: the same findings as SARIF 2.1.0 results
    WARNINGS = "warnings"  # compilers' `path:line:col: error: ...`, one a line, worst first


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
    OutputFormat.CODECLIMATE: codeclimate_report.render_scan,
    OutputFormat.SARIF: sarif_report.render_scan,
    OutputFormat.WARNINGS: warnings_report.render_scan,
}
assert set(_SCAN) == set(OutputFormat), "every output format needs a scan renderer"


def _safe(fmt: OutputFormat, text: str) -> str:
    """JSON (and Code Climate's and SARIF's JSON, ASCII) escapes control characters itself;
    every other format goes through
    :func:`~archmetrics.reports.printable.printable`."""
    json_formats = (OutputFormat.JSON, OutputFormat.CODECLIMATE, OutputFormat.SARIF)
    return text if fmt in json_formats else printable(text)


def render_scan(report: ScanReport, fmt: OutputFormat, grouping: Grouping) -> str:
    return _safe(fmt, _SCAN[fmt](report, grouping.value))


_DIFF: dict[OutputFormat, Callable[[DiffReport], str]] = {
    OutputFormat.TABLE: table_report.render_diff,
    OutputFormat.JSON: json_report.render_diff,
    OutputFormat.MARKDOWN: markdown_report.render_diff,
    OutputFormat.CSV: csv_report.render_diff,
    OutputFormat.CODECLIMATE: codeclimate_report.render_diff,
    OutputFormat.SARIF: sarif_report.render_diff,
    OutputFormat.WARNINGS: warnings_report.render_diff,
}
assert set(_DIFF) == set(OutputFormat), "every output format needs a diff renderer"


def render_diff(report: DiffReport, fmt: OutputFormat, max_rows: int | None = None) -> str:
    """``max_rows``: Markdown's changed elements, at most that many (0: all; None: as many
    as fit in a pull-request comment)."""
    if fmt is OutputFormat.MARKDOWN:
        return _safe(fmt, markdown_report.render_diff(report, max_rows))
    return _safe(fmt, _DIFF[fmt](report))


_SERIES: dict[OutputFormat, Callable[[SeriesReport], str]] = {
    OutputFormat.TABLE: table_report.render_series,
    OutputFormat.JSON: json_report.render_series,
    OutputFormat.MARKDOWN: markdown_report.render_series,
    OutputFormat.CSV: csv_report.render_series,
    OutputFormat.CODECLIMATE: codeclimate_report.render_series,
    OutputFormat.SARIF: sarif_report.render_series,
    OutputFormat.WARNINGS: warnings_report.render_series,
}
_COMPARE: dict[OutputFormat, Callable[[CompareReport], str]] = {
    OutputFormat.TABLE: table_report.render_compare,
    OutputFormat.JSON: json_report.render_compare,
    OutputFormat.MARKDOWN: markdown_report.render_compare,
    OutputFormat.CSV: csv_report.render_compare,
    OutputFormat.CODECLIMATE: codeclimate_report.render_compare,
    OutputFormat.SARIF: sarif_report.render_compare,
    OutputFormat.WARNINGS: warnings_report.render_compare,
}
assert set(_SERIES) == set(_COMPARE) == set(OutputFormat), "every format needs series/compare"


def render_series(report: SeriesReport, fmt: OutputFormat, max_rows: int | None = None) -> str:
    if fmt is OutputFormat.MARKDOWN:
        return _safe(fmt, markdown_report.render_series(report, max_rows))
    return _safe(fmt, _SERIES[fmt](report))


def render_compare(report: CompareReport, fmt: OutputFormat) -> str:
    return _safe(fmt, _COMPARE[fmt](report))


_ESTIMATE: dict[OutputFormat, Callable[[EstimateReport], str]] = {
    OutputFormat.TABLE: table_report.render_estimate,
    OutputFormat.JSON: json_report.render_estimate,
    OutputFormat.MARKDOWN: markdown_report.render_estimate,
    OutputFormat.CSV: csv_report.render_estimate,
    OutputFormat.CODECLIMATE: codeclimate_report.render_estimate,
    OutputFormat.SARIF: sarif_report.render_estimate,
    OutputFormat.WARNINGS: warnings_report.render_estimate,
}
assert set(_ESTIMATE) == set(OutputFormat), "every output format needs an estimate renderer"


def render_estimate(report: EstimateReport, fmt: OutputFormat) -> str:
    return _safe(fmt, _ESTIMATE[fmt](report))
