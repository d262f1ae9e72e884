"""Failed gates and thresholds as findings located in the code: what the code-scanning
formats (Code Climate for GitLab, SARIF for GitHub) and the compilers' warning lines report,
each in its own shape.

Every finding names a file and a line where there is one to name:

- a scan's function or file threshold: the function's file and line, the file;
- an element's threshold: the element's file that contributes most to the field (the
  highest v_g for ``vg``, the most lines for ``loc`` ...), and the message says so;
- a threshold on the total: the tree's file that contributes most to the field;
- a diff's gate, which is about the whole change: the configuration file and line that set
  it when it is configured; else the file the change touched most; else the largest file
  measured. The message says which.

Only a finding about nothing measured at all (an empty tree) has no file (``path`` None).
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from archmetrics.changeset.gates import GateFailure
from archmetrics.changeset.model import ElementChange
from archmetrics.complexity import FileMetrics, Totals
from archmetrics.complexity.thresholds import ThresholdFailure
from archmetrics.reports.model import CompareReport, DiffReport, EstimateReport, ScanReport


@dataclass(frozen=True, slots=True)
class Finding:
    rule: str  # the threshold or gate as written: ``vg(function) > 15``, ``cost(new) > 20``
    message: str
    path: str | None  # None: nothing measured to show it at
    line: int
    identity: str  # what makes it the same finding in the next run
    placed: str = ""  # why a finding about a whole element, tree or change is shown here
    excess: float = 0.0  # how far past its limit (worst first)
    fields: tuple[str, ...] = ()  # the fields the rule reads

    @property
    def fingerprint(self) -> str:
        text = f"archmetrics {self.rule}\0{self.identity}"
        return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()

    @property
    def text(self) -> str:
        """The message with where it is shown, when that is not its own place."""
        return f"{self.message} ({self.placed})" if self.placed else self.message


def worst_first(findings: Iterable[Finding]) -> list[Finding]:
    """The furthest past its limit first; ties by file, line and rule."""
    return sorted(findings, key=lambda f: (-f.excess, f.path or "", f.line, f.rule))


_NAMES = {"vg": "highest v_g", "loc": "most logical lines", "sloc": "most SLOC",
          "functions": "most functions", "warnings": "most warnings"}  # fmt: skip


def _measure(field: str) -> Callable[[FileMetrics], float] | None:
    """How much one file contributes to ``field`` (None: it cannot tell one from another)."""
    if field in ("vg", "loc", "sloc"):
        return lambda f: float(getattr(f, field))
    if field in ("functions", "warnings"):
        return lambda f: float(len(getattr(f, field)))
    if field == "unparsed":
        return lambda f: float(not f.parsed)
    if field == "files":
        return lambda f: float(f.loc)
    return None


def top_file(files: Sequence[FileMetrics], field: str) -> tuple[FileMetrics, str] | None:
    """The file of ``files`` contributing most to ``field`` and how to say so; the first
    file when the field is not a sum over files (coupling)."""
    if not files:
        return None
    measure = _measure(field)
    if measure is None:
        return files[0], "its first file"
    top = max(files, key=lambda f: (measure(f), -files.index(f)))
    words = {"unparsed": "a file that could not be parsed", "files": "its largest file"}
    return top, words.get(field) or f"its file with the {_NAMES[field]}"


def _scan_finding(
    report: ScanReport,
    failure: ThresholdFailure,
    by_path: dict[str, FileMetrics],
    element_files: dict[str, tuple[str, ...]],
    stage: str = "",
) -> Finding:
    unit, kind = failure.unit, failure.threshold.unit
    numbers = ", ".join(f"{f} = {unit.values[f]}" for f in failure.threshold.fields)
    # where it is: the finding's location says (a file's name is its path)
    said = numbers if kind == "file" else f"{unit.name} ({numbers})"
    message = f"{failure.threshold.text}: {said}"
    message = f"{stage}: {message}" if stage else message
    fields = failure.threshold.fields
    path, line, placed = unit.path, unit.line or 1, ""
    if kind in ("element", "total"):
        members = element_files.get(unit.name, ()) if kind == "element" else tuple(by_path)
        top = top_file([by_path[p] for p in members if p in by_path], fields[0])
        whole = f"element {unit.name}" if kind == "element" else "the whole tree"
        path, line = (top[0].path, 1) if top else (None, 1)
        placed = f"{whole}; shown at {top[1]}" if top else f"{whole}; nothing measured"
    identity = f"{unit.name}\0{unit.path or '.'}" + (f"\0{stage}" if stage else "")
    return Finding(failure.threshold.text, message, path, line, identity, placed,
                   failure.excess, fields)  # fmt: skip


def unit_findings(failures: Iterable[ThresholdFailure], stage: str = "") -> list[Finding]:
    """A diff's touched functions and files over a unit gate, each where it is."""
    empty = ScanReport("", "", (), (), Totals(0, 0, 0, 0, 0, 0, 0))
    return [_scan_finding(empty, f, {}, {}, stage) for f in failures]


def scan_findings(report: ScanReport) -> list[Finding]:
    """Every unit over a threshold, where it is (worst first within each threshold)."""
    if not report.failures:
        return []
    by_path = {f.path: f for f in report.files}
    element_files = {r.element: r.files for r in report.element_rows()}
    return [_scan_finding(report, f, by_path, element_files) for f in report.failures]


def _most_changed(report: DiffReport) -> str | None:
    """The file of the element with the most statements added, removed and modified."""
    changed = [e for e in report.change.changed() if e.files and e.added + e.removed + e.modified]
    if not changed:
        return None
    top = max(changed, key=lambda e: (e.added + e.removed + e.modified, e.element))
    return top.files[0]


def _size(change: ElementChange) -> int:
    """λ after the change (before it, for an element the change removed)."""
    return (change.post.loc if change.post else 0) or (change.pre.loc if change.pre else 0)


def _largest(report: DiffReport) -> str | None:
    """The first file of the largest element after the change."""
    elements = [e for e in report.change.elements if e.files]
    return max(elements, key=lambda e: (_size(e), e.element)).files[0] if elements else None


def gate_place(report: DiffReport, gate: str) -> tuple[str | None, int, str]:
    """Where a failed gate of ``report`` is shown, and why there."""
    origin = report.origin(gate)
    if origin is not None:
        return origin.path, origin.line, f"the change as a whole; the gate is set in {origin.path}"
    most = _most_changed(report)
    if most is not None:
        return most, 1, "the change as a whole; shown at the file it changed most"
    largest = _largest(report)
    if largest is not None:
        return largest, 1, "the change as a whole; it changed no file: shown at its largest file"
    return None, 1, "the change as a whole; nothing was measured"


def _gates(failures: Iterable[GateFailure], report: DiffReport, stage: str = "") -> list[Finding]:
    found = []
    for failure in failures:
        message = str(failure).removeprefix("gate failed: ")
        if stage:
            message = f"{stage}: {message}"
        path, line, placed = gate_place(report, failure.gate.text)
        fields = tuple(dict.fromkeys(c.field for g in failure.gate.groups for c in g))
        found.append(Finding(failure.gate.text, message, path, line, stage, placed, 0.0, fields))
    return found


def diff_findings(report: DiffReport) -> list[Finding]:
    """Every failed gate of the change, and every touched unit over a unit gate."""
    return _gates(report.failures, report) + unit_findings(report.offenders)


def compare_findings(report: CompareReport) -> list[Finding]:
    """Every failed gate of every stage, named by its approach and stage."""
    found = []
    for approach, series in report.series:
        for stage in series.stages:
            name = f"{approach} {stage.label}".strip()
            found += _gates(stage.report.failures, stage.report, name)
            found += unit_findings(stage.report.offenders, name)
    return found


def estimate_findings(report: EstimateReport) -> list[Finding]:
    """Every failed gate of every architecture's stage: an estimate has no code of its own,
    so each is shown at the plan file when the repository holds it (else as a diff's)."""
    found = compare_findings(report.compare())
    if report.plan_path is None:
        return found
    placed = "an estimate; shown at the plan"
    return [
        Finding(f.rule, f.message, report.plan_path, 1, f.identity, placed, f.excess, f.fields)
        for f in found
    ]
