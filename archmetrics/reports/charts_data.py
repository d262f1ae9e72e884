"""What a chart shows, as plain values: the numbers, their gaps and the conventions behind them.

Pure (no matplotlib): a value is read from a stage's :class:`Summary`; it is a *gap* (None, drawn
as "n/a", never as 0) when it is undefined, and it carries the notes of the conventions it rests
on (λ̂ undefined, E = 0 by eq. 6.38, ...) so the chart can footnote them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from archmetrics.changeset.locations import Location
from archmetrics.changeset.model import Summary
from archmetrics.changeset.scope import scope_summary
from archmetrics.reports.model import CompareReport, SeriesReport

LOCATIONS = ("base", "new", "framework")


@dataclass(frozen=True, slots=True)
class Measure:
    """One Summary field as charted: its thesis symbols (mathtext), name and unit."""

    field: str
    symbol: str  # of a location, e.g. Γ'(L)
    total: str  # of the total, e.g. Γ'_tot
    name: str
    unit: str


COUPLING = (
    Measure("delta_s_a", r"$\Delta s_a$", r"$\Delta s_{a,tot}$", "static afferent", "links"),
    Measure("delta_s_e", r"$\Delta s_e$", r"$\Delta s_{e,tot}$", "static efferent", "links"),
    Measure("delta_d_a", r"$\Delta d_a$", r"$\Delta d_{a,tot}$", "dynamic afferent", "links"),
    Measure("delta_d_e", r"$\Delta d_e$", r"$\Delta d_{e,tot}$", "dynamic efferent", "links"),
)
SCALED_CHANGES = Measure(
    "scaled_changes",
    r"$\Gamma'$",
    r"$\Gamma'_{tot}$",
    "scaled code size change",
    r"logical lines $\times\ \hat{\lambda}$",
)
SCALED_COMPLEXITY = Measure(
    "scaled_delta_vg",
    r"$\Delta V_g'$",
    r"$\Delta V_{g,tot}'$",
    "scaled complexity change",
    r"McCabe $v_g \times\ \hat{v}_g$",
)
COST = Measure("cost", r"$E$", r"$E_{tot}$", "complexity change cost", r"$\Gamma'\,/\,\Delta V_g'$")

_COUPLING_FIELDS = frozenset(m.field for m in COUPLING)
_SIZE = frozenset({"scaled_changes", "cost"})
_COMPLEXITY = frozenset({"scaled_delta_vg", "cost"})
_ALL = frozenset({*_COUPLING_FIELDS, *_SIZE, *_COMPLEXITY})

# note code -> the charted fields whose value rests on that convention (cost.py, compute.py)
CONVENTIONS: dict[str, frozenset[str]] = {
    "location_empty": _ALL,
    "loc_scale_undefined_pre_zero": _SIZE,
    "loc_scale_zero_post_empty": _SIZE,
    "vg_scale_undefined_pre_zero": _COMPLEXITY,
    "vg_scale_zero_post_empty": _COMPLEXITY,
    "cost_zero_no_complexity_change": frozenset({"cost"}),
    "cost_negative_complexity_decreased": frozenset({"cost"}),
    "dynamic_pre_zero": frozenset({"delta_d_a", "delta_d_e"}),
}
CONVENTION_NAMES: dict[str, str] = {
    "location_empty": "empty location",
    "loc_scale_undefined_pre_zero": "λ̂ undefined",
    "loc_scale_zero_post_empty": "λ̂ = 0",
    "vg_scale_undefined_pre_zero": "v̂g undefined",
    "vg_scale_zero_post_empty": "v̂g = 0",
    "cost_zero_no_complexity_change": "E = 0 by convention",
    "cost_negative_complexity_decreased": "E < 0",
    "dynamic_pre_zero": "dynamic coupling before taken as 0",
}
# note code prefix -> the fields it leaves undefined (their values are placeholders, not data)
UNDEFINED: dict[str, frozenset[str]] = {"coupling_not_measured": _COUPLING_FIELDS}


@dataclass(frozen=True, slots=True)
class Value:
    """One bar: its number, or None with the reason it is a gap; and the conventions used."""

    number: float | None
    gap: str = ""
    conventions: tuple[str, ...] = ()  # the full notes ("code: text") it rests on


def note_code(note: str) -> str:
    return note.partition(":")[0].strip()


def read_value(summary: Summary | None, field: str, missing: str = "") -> Value:
    """The charted value of ``field``; ``summary`` None means the stage does not exist."""
    if summary is None:
        return Value(None, missing or "no such stage")
    for note in summary.notes:
        code = note_code(note)
        if any(code.startswith(p) and field in fs for p, fs in UNDEFINED.items()):
            return Value(None, note.partition(":")[2].strip() or code)
    number = getattr(summary, field)
    if number is None or not math.isfinite(number):
        return Value(None, f"{field} undefined")
    used = tuple(n for n in summary.notes if field in CONVENTIONS.get(note_code(n), ()))
    return Value(float(number), "", used)


def stage_labels(report: CompareReport) -> tuple[str, ...]:
    """Every stage label of every series, in order of first appearance."""
    seen: dict[str, None] = {}
    for _, series in report.series:
        for stage in series.stages:
            seen.setdefault(stage.label, None)
    return tuple(seen)


def stage_revisions(report: CompareReport, stages: tuple[str, ...]) -> tuple[str | None, ...]:
    """The revision each stage measured (its head), where every series that has the stage
    measured the same one and it is not the stage's label already; else None."""
    heads: dict[str, set[str]] = {}
    for _, series in report.series:
        for stage in series.stages:
            heads.setdefault(stage.label, set()).add(stage.report.head)
    found: list[str | None] = []
    for label in stages:
        revisions = heads.get(label, set())
        only = next(iter(revisions)) if len(revisions) == 1 else None
        found.append(only if only != label else None)
    return tuple(found)


def summary_at(series: SeriesReport, stage: str, location: str) -> Summary | None:
    """S(location) of the named stage, or None when the series has no such stage."""
    for s in series.stages:
        if s.label == stage:
            return s.report.summaries()[location]
    return None


def stage_value(
    series: SeriesReport, approach: str, stage: str, location: str, field: str
) -> Value:
    return read_value(
        summary_at(series, stage, location), field, f"{approach} has no stage {stage!r}"
    )


@dataclass(frozen=True, slots=True)
class Scope:
    """The locations a summary chart adds up, and how its symbols and title say so: the
    thesis's totals (Figs 8.1-8.4) are over base, new and framework; the study judges its
    findings on base + framework (docs/study.md), and charts them there."""

    locations: tuple[Location, ...]
    subscript: str  # in the symbols: E_{tot}, E_{B+F}
    label: str  # in the title

    def symbol(self, measure: Measure) -> str:
        """The measure's total symbol with this scope's subscript (``$E_{B+F}$``)."""
        return measure.total.replace("tot}", f"{self.subscript}}}")

    def value(self, series: SeriesReport, approach: str, stage: str, field: str) -> Value:
        """The charted value of ``field`` over this scope's locations at ``stage``."""
        if self.locations == TOTAL.locations:
            return stage_value(series, approach, stage, "total", field)
        for s in series.stages:
            if s.label == stage:
                return read_value(scope_summary(s.report.change, self.locations), field)
        return read_value(None, field, f"{approach} has no stage {stage!r}")


TOTAL = Scope(
    (Location.BASE, Location.NEW, Location.FRAMEWORK), "tot", "total of base, new and framework"
)
INTEGRATION = Scope((Location.BASE, Location.FRAMEWORK), "B+F", "base + framework")
