"""Compilers' warning lines: one ``path:line:col: error: message`` line per offender, the
worst first, and nothing else (lizard's ``-w``, gcc's and clang's format): editors and CI
logs make each line a link to the code. Offenders are the failed thresholds and gates, each
at the place reports/findings.py gives (a whole change's gate at the configuration line that
sets it, or at the file it touched most); a run with none prints nothing. The column is 1:
archmetrics knows lines, not columns. Functions a suppression comment exempts and offenders
the baseline knows are not offenders: the other formats list them.
"""

from __future__ import annotations

from archmetrics.reports.findings import (
    Finding,
    compare_findings,
    diff_findings,
    estimate_findings,
    scan_findings,
    worst_first,
)
from archmetrics.reports.model import (
    CompareReport,
    DiffReport,
    EstimateReport,
    ScanReport,
    SeriesReport,
)
from archmetrics.reports.printable import one_line


def _lines(findings: list[Finding]) -> str:
    return "".join(
        f"{f.path or '.'}:{f.line}:1: error: {one_line(f.text)}\n" for f in worst_first(findings)
    )


def render_scan(report: ScanReport, grouping: str = "file") -> str:
    return _lines(scan_findings(report))


def render_diff(report: DiffReport) -> str:
    return _lines(diff_findings(report))


def render_series(report: SeriesReport) -> str:
    return render_compare(CompareReport((("", report),)))


def render_compare(report: CompareReport) -> str:
    return _lines(compare_findings(report))


def render_estimate(report: EstimateReport) -> str:
    return _lines(estimate_findings(report))
