"""SARIF 2.1.0 (GitHub code scanning): each failed gate or threshold as a result.

One run of the ``archmetrics`` tool; one rule per threshold or gate as written (its id is
the text, ``vg(function) > 15``, the same in every run), with help text saying what its
fields count and how to act, and a ``helpUri`` into the docs; one result per finding, at
level ``error`` (a gate the team set failed), worst first, located at the file and line
reports/findings.py gives: GitHub refuses a file whose results lack a location, so a gate
about the whole change is shown at the configuration file that sets it or at the file the
change touched most, and its message says so. A finding about nothing measured at all (an
empty tree) has no file to show: it becomes a notification of the run instead of a result.
``partialFingerprints`` carry the same fingerprint as the Code Climate report, so an alert
keeps its identity across runs. Nothing failed: a run with no results.
"""

from __future__ import annotations

import json
from typing import Any

from archmetrics import __version__
from archmetrics.reports.findings import (
    Finding,
    compare_findings,
    diff_findings,
    estimate_findings,
    scan_findings,
    worst_first,
)
from archmetrics.reports.glossary import help_uri, meaning
from archmetrics.reports.model import (
    CompareReport,
    DiffReport,
    EstimateReport,
    ScanReport,
    SeriesReport,
)

SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
FINGERPRINT = "archmetrics/v1"
MAX_RESULTS = 25_000  # GitHub refuses a run with more; the rest are counted in a notification


def _location(finding: Finding) -> dict[str, Any]:
    physical = {
        "artifactLocation": {"uri": finding.path, "uriBaseId": "%SRCROOT%"},
        "region": {"startLine": max(1, finding.line)},
    }
    return {"physicalLocation": physical}


def _help(finding: Finding) -> str:
    """What the rule's fields count and how to act on a failure."""
    fields = "; ".join(meaning(field) for field in finding.fields)
    act = (
        "Lower the value, or if the code was reviewed and stays: a baseline (`archmetrics"
        " baseline`) keeps the offenders a code base already has, and `archmetrics: ignore[FIELD]`"
        " on or above a function's definition exempts that one function."
    )
    return f"archmetrics gate or threshold `{finding.rule}` failed. {fields}. {act}"


def _rule(rule: str, finding: Finding) -> dict[str, Any]:
    text = _help(finding)
    described: dict[str, Any] = {
        "id": rule,
        "name": "ArchmetricsGate",
        "shortDescription": {"text": f"archmetrics gate or threshold: {rule}"[:1024]},
        "fullDescription": {"text": text[:1024]},
        "help": {"text": text, "markdown": text},
        "defaultConfiguration": {"level": "error"},
    }
    uri = help_uri("ci.md", "gates")
    if uri:
        described["helpUri"] = uri
    return described


def _document(findings: list[Finding]) -> dict[str, Any]:
    located = worst_first(f for f in findings if f.path is not None)
    shown, left = located[:MAX_RESULTS], located[MAX_RESULTS:]
    first = {f.rule: f for f in reversed(shown)}
    rules = list(dict.fromkeys(f.rule for f in shown))
    index = {rule: i for i, rule in enumerate(rules)}
    results = [
        {
            "ruleId": f.rule,
            "ruleIndex": index[f.rule],
            "level": "error",
            "message": {"text": f.text},
            "locations": [_location(f)],
            "partialFingerprints": {FINGERPRINT: f.fingerprint},
        }
        for f in shown
    ]
    notes = [f.text for f in findings if f.path is None]
    if left:
        notes.append(f"{len(left)} more results left out (GitHub takes {MAX_RESULTS:,} a run)")
    driver: dict[str, Any] = {"name": "archmetrics", "version": __version__}
    information = help_uri("ci.md", "code-scanning---format-sarif")
    if information:
        driver["informationUri"] = information
    driver["rules"] = [_rule(rule, first[rule]) for rule in rules]
    run: dict[str, Any] = {"tool": {"driver": driver}, "results": results}
    if notes:
        run["invocations"] = [
            {
                "executionSuccessful": True,
                "toolExecutionNotifications": [
                    {"level": "error", "message": {"text": note}} for note in notes
                ],
            }
        ]
    return {"$schema": SCHEMA, "version": "2.1.0", "runs": [run]}


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
    return _dump(estimate_findings(report))
