"""SARIF 2.1.0 (GitHub code scanning): each failed gate or threshold as a result.

One run of the ``archmetrics`` tool; one rule per threshold or gate as written (its id is
the text, ``vg(function) > 15``); one result per finding, at level ``error`` (a gate the team
set failed), located at the file and line reports/findings.py gives. GitHub shows only
results that name a file: a diff's gate, which is about the whole change, is located at line
1 of the file the change touched most, and its message says so; a gate that failed on a
change touching no file has no location. ``partialFingerprints`` carry the same fingerprint
as the Code Climate report, so an alert keeps its identity across runs. Nothing failed: a
run with no results. docs/ci.md shows the workflow step that uploads it.
"""

from __future__ import annotations

import json
from typing import Any

from archmetrics import __version__
from archmetrics.reports.findings import Finding, compare_findings, diff_findings, scan_findings
from archmetrics.reports.model import (
    CompareReport,
    DiffReport,
    EstimateReport,
    ScanReport,
    SeriesReport,
)

SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
FINGERPRINT = "archmetrics/v1"


def _location(finding: Finding) -> list[dict[str, Any]]:
    path = finding.path or finding.most_changed
    if path is None:
        return []
    physical = {
        "artifactLocation": {"uri": path, "uriBaseId": "%SRCROOT%"},
        "region": {"startLine": finding.line},
    }
    return [{"physicalLocation": physical}]


def _message(finding: Finding) -> str:
    if finding.path is None and finding.most_changed is not None:
        return f"{finding.message} (the change as a whole; shown at the file it changed most)"
    return finding.message


def _document(findings: list[Finding]) -> dict[str, Any]:
    rules = list(dict.fromkeys(f.rule for f in findings))
    index = {rule: i for i, rule in enumerate(rules)}
    results = [
        {
            "ruleId": f.rule,
            "ruleIndex": index[f.rule],
            "level": "error",
            "message": {"text": _message(f)},
            "locations": _location(f),
            "partialFingerprints": {FINGERPRINT: f.fingerprint},
        }
        for f in findings
    ]
    driver = {
        "name": "archmetrics",
        "version": __version__,
        "rules": [
            {
                "id": rule,
                "name": "ArchmetricsGate",
                "shortDescription": {"text": f"archmetrics gate or threshold: {rule}"},
                "defaultConfiguration": {"level": "error"},
            }
            for rule in rules
        ],
    }
    return {
        "$schema": SCHEMA,
        "version": "2.1.0",
        "runs": [{"tool": {"driver": driver}, "results": results}],
    }


def _dump(findings: list[Finding]) -> str:
    return json.dumps(_document(findings), indent=2) + "\n"  # ASCII: any name survives


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
    return render_compare(report.compare())
