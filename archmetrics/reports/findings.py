"""Failed gates and thresholds as findings located in the code: what the code-scanning
formats (Code Climate for GitLab, SARIF for GitHub) report, each in its own shape.

A scan's threshold failure is located at its function's file and line, its file, or its
element's first file. A diff's gate is about the whole change: it has no place of its own
(``path`` None); a format that must name a file names the file the change touched most
(:attr:`Finding.most_changed`).
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from dataclasses import dataclass

from archmetrics.changeset.gates import GateFailure
from archmetrics.reports.model import CompareReport, DiffReport, ScanReport


@dataclass(frozen=True, slots=True)
class Finding:
    rule: str  # the threshold or gate as written: ``vg(function) > 15``, ``cost(new) > 20``
    message: str
    path: str | None  # None: the change as a whole (a diff's gate)
    line: int
    identity: str  # what makes it the same finding in the next run
    most_changed: str | None = None  # a gate's: the file its change touched most

    @property
    def fingerprint(self) -> str:
        text = f"archmetrics {self.rule}\0{self.identity}"
        return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


def scan_findings(report: ScanReport) -> list[Finding]:
    """Every unit over a threshold, where it is."""
    if not report.failures:
        return []
    first_file = {r.element: r.files[0] for r in report.element_rows() if r.files}
    found = []
    for failure in report.failures:
        unit = failure.unit
        path = unit.path or first_file.get(unit.name)
        message = str(failure).removeprefix("gate failed: ")
        identity = f"{unit.name}\0{path or '.'}"
        found.append(Finding(failure.threshold.text, message, path, unit.line or 1, identity))
    return found


def _most_changed(report: DiffReport) -> str | None:
    """The file of the element with the most statements added, removed and modified."""
    changed = [e for e in report.change.changed() if e.files and e.added + e.removed + e.modified]
    if not changed:
        return None
    top = max(changed, key=lambda e: (e.added + e.removed + e.modified, e.element))
    return top.files[0]


def _gates(failures: Iterable[GateFailure], report: DiffReport, stage: str = "") -> list[Finding]:
    found = []
    for failure in failures:
        message = str(failure).removeprefix("gate failed: ")
        if stage:
            message = f"{stage}: {message}"
        found.append(Finding(failure.gate.text, message, None, 1, stage, _most_changed(report)))
    return found


def diff_findings(report: DiffReport) -> list[Finding]:
    """Every failed gate of the change."""
    return _gates(report.failures, report)


def compare_findings(report: CompareReport) -> list[Finding]:
    """Every failed gate of every stage, named by its approach and stage."""
    found = []
    for approach, series in report.series:
        for stage in series.stages:
            name = f"{approach} {stage.label}".strip()
            found += _gates(stage.report.failures, stage.report, name)
    return found
