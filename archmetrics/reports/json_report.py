"""JSON: the machine-readable contract (versioned by its ``schema`` field; see docs/json.md)."""

from __future__ import annotations

import json
from typing import Any

from archmetrics.complexity import FileMetrics, Totals
from archmetrics.facts import ParseWarning
from archmetrics.reports.model import SCAN_SCHEMA, ScanReport


def warning_dict(warning: ParseWarning) -> dict[str, Any]:
    return {
        "path": warning.path,
        "line": warning.line,
        "severity": str(warning.severity),
        "message": warning.message,
    }


def _file(metrics: FileMetrics) -> dict[str, Any]:
    return {
        "path": metrics.path,
        "language": metrics.language,
        "loc": metrics.loc,
        "sloc": metrics.sloc,
        "vg": metrics.vg,
        "parsed": metrics.parsed,
        "generated": metrics.generated,
        "functions": [
            {
                "name": f.name,
                "qualified_name": f.qualified_name,
                "line": f.line,
                "end_line": f.end_line,
                "loc": f.loc,
                "vg": f.vg,
            }
            for f in metrics.functions
        ],
        "warnings": [warning_dict(w) for w in metrics.warnings],
    }


def totals_dict(totals: Totals) -> dict[str, Any]:
    return {
        "files": totals.files,
        "functions": totals.functions,
        "loc": totals.loc,
        "sloc": totals.sloc,
        "vg": totals.vg,
        "warnings": totals.warnings,
        "unparsed": totals.unparsed,
    }


def scan_dict(report: ScanReport) -> dict[str, Any]:
    return {
        "schema": SCAN_SCHEMA,
        "root": report.root,
        "revision": report.revision,
        "files": [_file(f) for f in report.files],
        "totals": totals_dict(report.totals),
    }


def dumps(document: dict[str, Any]) -> str:
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


def render_scan(report: ScanReport) -> str:
    return dumps(scan_dict(report))
