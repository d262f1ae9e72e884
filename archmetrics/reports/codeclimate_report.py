"""Code Climate JSON (GitLab Code Quality): each failed gate or threshold as an issue.

GitLab reads a JSON array of issues, each with a ``description``, a ``check_name``, a
``fingerprint`` (the same finding in the next pipeline has the same one), a ``severity`` and
a ``location`` (a path relative to the repository and a line). A scan's threshold failure is
located at its function's file and line, its file, or its element's first file; a diff's
gate, which is about the whole change, at the repository (``.``, line 1). Nothing failed:
an empty array. docs/ci.md shows the GitLab job that uploads it.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable
from typing import Any

from archmetrics.changeset.gates import GateFailure
from archmetrics.reports.model import (
    CompareReport,
    DiffReport,
    EstimateReport,
    ScanReport,
    SeriesReport,
)

SEVERITY = "major"  # a gate the team set failed: the pipeline fails too


def _issue(check: str, description: str, path: str, line: int, identity: str) -> dict[str, Any]:
    fingerprint = hashlib.sha256(f"{check}\0{identity}".encode("utf-8", "surrogatepass"))
    return {
        "type": "issue",
        "check_name": check,
        "description": description,
        "categories": ["Complexity"],
        "fingerprint": fingerprint.hexdigest(),
        "severity": SEVERITY,
        "location": {"path": path, "lines": {"begin": line}},
    }


def _dump(issues: list[dict[str, Any]]) -> str:
    return json.dumps(issues, indent=2) + "\n"  # ASCII: any name survives


def render_scan(report: ScanReport, grouping: str = "file") -> str:
    """Every unit over a threshold, where it is."""
    if not report.failures:
        return _dump([])
    first_file = {r.element: r.files[0] for r in report.element_rows() if r.files}
    issues = []
    for failure in report.failures:
        unit = failure.unit
        path = unit.path or first_file.get(unit.name, ".")
        description = str(failure).removeprefix("gate failed: ")
        check = f"archmetrics {failure.threshold.text}"
        issues.append(_issue(check, description, path, unit.line or 1, f"{unit.name}\0{path}"))
    return _dump(issues)


def _gates(failures: Iterable[GateFailure], stage: str = "") -> list[dict[str, Any]]:
    issues = []
    for failure in failures:
        check = f"archmetrics {failure.gate.text}"
        description = str(failure).removeprefix("gate failed: ")
        if stage:
            description = f"{stage}: {description}"
        issues.append(_issue(check, description, ".", 1, stage))
    return issues


def render_diff(report: DiffReport) -> str:
    """Every failed gate of the change."""
    return _dump(_gates(report.failures))


def render_series(report: SeriesReport) -> str:
    return render_compare(CompareReport((("", report),)))


def render_compare(report: CompareReport) -> str:
    """Every failed gate of every stage, named by its approach and stage."""
    issues = []
    for approach, series in report.series:
        for stage in series.stages:
            name = f"{approach} {stage.label}".strip()
            issues += _gates(stage.report.failures, name)
    return _dump(issues)


def render_estimate(report: EstimateReport) -> str:
    """Every failed gate of every architecture's stage (estimated figures)."""
    return render_compare(report.compare())
