"""Code Climate JSON (GitLab Code Quality): each failed gate or threshold as an issue.

GitLab reads a JSON array of issues, each with a ``description``, a ``check_name``, a
``fingerprint`` (the same finding in the next pipeline has the same one), a ``severity`` and
a ``location`` (a path relative to the repository and a line). Where each finding is located
is reports/findings.py's: a diff's gate, which is about the whole change, at the
configuration file that sets it or the file the change touched most (the description says
so); only a finding with no file to show (an empty tree) at the repository (``.``, line 1).
Nothing failed: an empty array. docs/ci.md shows the GitLab job that uploads
it.
"""

from __future__ import annotations

import json
from typing import Any

from archmetrics.reports.findings import (
    Finding,
    compare_findings,
    diff_findings,
    estimate_findings,
    scan_findings,
)
from archmetrics.reports.model import (
    CompareReport,
    DiffReport,
    EstimateReport,
    ScanReport,
    SeriesReport,
)

SEVERITY = "major"  # a gate the team set failed: the pipeline fails too


def _issue(finding: Finding) -> dict[str, Any]:
    return {
        "type": "issue",
        "check_name": f"archmetrics {finding.rule}",
        "description": finding.text,
        "categories": ["Complexity"],
        "fingerprint": finding.fingerprint,
        "severity": SEVERITY,
        "location": {"path": finding.path or ".", "lines": {"begin": finding.line}},
    }


def _dump(findings: list[Finding]) -> str:
    return json.dumps([_issue(f) for f in findings], indent=2) + "\n"  # ASCII: any name survives


def render_scan(report: ScanReport, grouping: str = "file") -> str:
    """Every unit over a threshold, where it is."""
    return _dump(scan_findings(report))


def render_diff(report: DiffReport) -> str:
    """Every failed gate of the change."""
    return _dump(diff_findings(report))


def render_series(report: SeriesReport) -> str:
    return render_compare(CompareReport((("", report),)))


def render_compare(report: CompareReport) -> str:
    """Every failed gate of every stage, named by its approach and stage."""
    return _dump(compare_findings(report))


def render_estimate(report: EstimateReport) -> str:
    """Every failed gate of every architecture's stage (estimated figures)."""
    return _dump(estimate_findings(report))
