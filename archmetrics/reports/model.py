"""What reports render: plain frozen values built by the use cases."""

from __future__ import annotations

from dataclasses import dataclass

from archmetrics.changeset.accuracy import ChangeAccuracy
from archmetrics.changeset.gates import GateFailure, GateOrigin
from archmetrics.changeset.history import CommitStep
from archmetrics.changeset.model import ChangeReport, ExcludedFile, Summary
from archmetrics.complexity import FileMetrics, Totals
from archmetrics.complexity.thresholds import ThresholdFailure
from archmetrics.coupling import CouplingReport
from archmetrics.facts import FileFacts, ParseWarning

SCAN_SCHEMA = "archmetrics.scan/1"
DIFF_SCHEMA = "archmetrics.diff/1"
SERIES_SCHEMA = "archmetrics.series/1"
COMPARE_SCHEMA = "archmetrics.compare/1"
LOCATION_COLUMNS = ("base", "new", "framework", "total")


@dataclass(frozen=True, slots=True)
class ScanReport:
    """One snapshot measured: facts (for tracing) and the metrics shown."""

    root: str
    revision: str
    facts: tuple[FileFacts, ...]
    files: tuple[FileMetrics, ...]
    totals: Totals
    coupling: CouplingReport | None = None
    excluded: tuple[ExcludedFile, ...] = ()  # left out by the configuration's `exclude`
    gates: tuple[str, ...] = ()  # the thresholds checked (--fail-on)
    failures: tuple[ThresholdFailure, ...] = ()  # every unit that failed one
    suppressed: tuple[ThresholdFailure, ...] = ()  # would fail: a comment exempts them
    baselined: tuple[ThresholdFailure, ...] = ()  # would fail: the baseline knows them
    notes: tuple[str, ...] = ()  # what the reader should know: nothing to measure

    def element_rows(self) -> list[ElementRow]:
        """Per element: its files, summed λ, SLOC and v_g, and its coupling."""
        if self.coupling is None:
            return []
        by_path = {f.path: f for f in self.files}
        rows = []
        for c in self.coupling.elements:
            files = [by_path[p] for p in c.element.files if p in by_path]
            rows.append(
                ElementRow(
                    c.element.name,
                    c.element.files,
                    sum(f.loc for f in files),
                    sum(f.sloc for f in files),
                    sum(f.vg for f in files),
                    c.s_a,
                    c.s_e,
                    c.d_a,
                    c.d_e,
                )
            )
        return rows


@dataclass(frozen=True, slots=True)
class ElementRow:
    element: str
    files: tuple[str, ...]
    loc: int
    sloc: int
    vg: int
    s_a: int
    s_e: int
    d_a: int
    d_e: int


@dataclass(frozen=True, slots=True)
class DiffReport:
    """Two revisions compared: the chapter-6 metrics, and what could not be measured."""

    base: str
    head: str
    change: ChangeReport
    warnings: tuple[ParseWarning, ...] = ()
    gates: tuple[str, ...] = ()  # the gate expressions checked
    failures: tuple[GateFailure, ...] = ()
    offenders: tuple[ThresholdFailure, ...] = ()  # touched functions, files over a unit gate
    suppressed: tuple[ThresholdFailure, ...] = ()  # would fail: a comment exempts them
    baselined: tuple[ThresholdFailure, ...] = ()  # would fail: the baseline knows them
    origins: tuple[GateOrigin, ...] = ()  # where the configured gates are written
    commits: tuple[str | None, str | None] = (None, None)  # base's and head's commit ids

    @property
    def failed(self) -> tuple[GateFailure | ThresholdFailure, ...]:
        """Every failure: the location gates', then the touched units' (worst first)."""
        return (*self.failures, *self.offenders)

    def origin(self, gate: str) -> GateOrigin | None:
        """Where ``gate`` is written, if a configuration file sets it."""
        return next((o for o in self.origins if o.gate == gate), None)

    def summaries(self) -> dict[str, Summary]:
        """Per location and the total, keyed base, new, framework, total."""
        found = {loc.value: summary for loc, summary in self.change.locations}
        found["total"] = self.change.total
        return found


@dataclass(frozen=True, slots=True)
class Stage:
    """One stage of a series: its label and its diff against the stage before."""

    label: str
    report: DiffReport


@dataclass(frozen=True, slots=True)
class SeriesReport:
    repo: str
    stages: tuple[Stage, ...]

    @property
    def failures(self) -> tuple[GateFailure | ThresholdFailure, ...]:
        return tuple(f for s in self.stages for f in s.report.failed)


@dataclass(frozen=True, slots=True)
class CompareReport:
    """Several series side by side, e.g. the thesis's SOA, Player and P2P approaches."""

    series: tuple[tuple[str, SeriesReport], ...]

    @property
    def failures(self) -> tuple[GateFailure | ThresholdFailure, ...]:
        return tuple(f for _, s in self.series for f in s.failures)


ESTIMATE_SCHEMA = "archmetrics.estimate/1"


@dataclass(frozen=True, slots=True)
class ArchitectureEstimate:
    """One candidate architecture's estimate: a series of stages measured against the base.

    ``kind``: ``plan`` (planned counts applied to the measured base) or ``sketch:revision``,
    ``sketch:patch``, ``sketch:stubs`` (code measured as ``diff`` would). Either way an
    estimate, never the integration itself."""

    name: str
    kind: str
    series: SeriesReport
    description: str = ""


@dataclass(frozen=True, slots=True)
class EstimateFailure:
    """A gate that fails on one architecture's stage."""

    architecture: str
    stage: str
    failure: GateFailure

    def __str__(self) -> str:
        return f"{self.architecture} ({self.stage}): {self.failure}"


@dataclass(frozen=True, slots=True)
class Ranked:
    """One architecture's place for one stage: cheapest total E first (docs/estimate.md)."""

    stage: str
    rank: int
    architecture: str
    cost: float
    scaled_changes: float
    scaled_delta_vg: float


@dataclass(frozen=True, slots=True)
class EstimateReport:
    """``archmetrics estimate``: each architecture of a plan estimated against ``base``."""

    plan: str
    base: str
    architectures: tuple[ArchitectureEstimate, ...]
    gates: tuple[str, ...] = ()
    failures: tuple[EstimateFailure, ...] = ()
    actual: DiffReport | None = None  # --actual: the change measured afterwards
    accuracy: tuple[tuple[str, ChangeAccuracy], ...] = ()  # per architecture, against it
    plan_path: str | None = None  # the plan file relative to the repository (None: outside)

    def compare(self) -> CompareReport:
        """The architectures as series side by side (what series and compare render)."""
        return CompareReport(tuple((a.name, a.series) for a in self.architectures))

    def stage_labels(self) -> tuple[str, ...]:
        """Every stage label, in the order the architectures first name them."""
        labels: dict[str, None] = {}
        for architecture in self.architectures:
            for stage in architecture.series.stages:
                labels.setdefault(stage.label)
        return tuple(labels)

    def ranking(self) -> tuple[Ranked, ...]:
        """Per stage, the architectures by total E, then by Γ'_tot (fewer changes first)."""
        ranked: list[Ranked] = []
        for label in self.stage_labels():
            totals = [
                (a.name, s.report.change.total)
                for a in self.architectures
                for s in a.series.stages
                if s.label == label
            ]
            totals.sort(key=lambda item: (item[1].cost, item[1].scaled_changes, item[0]))
            ranked += [
                Ranked(label, i, name, t.cost, t.scaled_changes, t.scaled_delta_vg)
                for i, (name, t) in enumerate(totals, start=1)
            ]
        return tuple(ranked)


HISTORY_SCHEMA = "archmetrics.history/1"


@dataclass(frozen=True, slots=True)
class HistoryEntry:
    """One commit of a history against its first parent (``parent`` None: a root commit,
    against the empty tree), with the gates that fail on it."""

    commit: str
    parent: str | None
    time: int  # committer date, seconds since the epoch (UTC)
    subject: str
    merge: bool
    step: CommitStep
    failures: tuple[GateFailure, ...] = ()


@dataclass(frozen=True, slots=True)
class HistoryReport:
    """Every commit of a range, oldest first. ``measured``: how many commits this run
    measured (the others' steps were kept from an earlier run); ``parsed``: how many file
    versions it parsed."""

    repo: str
    range: str
    entries: tuple[HistoryEntry, ...]
    gates: tuple[str, ...] = ()
    measured: int = 0
    parsed: int = 0

    @property
    def failures(self) -> tuple[GateFailure, ...]:
        return tuple(f for e in self.entries for f in e.failures)
