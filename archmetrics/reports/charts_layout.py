"""How each chart kind is organised: which panels, which bar groups, which bars (pure values).

The organisation follows the thesis's figures (Hestand 2011, chapters 7-12):

* coupling -- per approach, the four coupling changes by location (Figs 7.1-7.3, 9.1-9.3);
  here one row of panels per approach, one column per stage.
* scaled size / complexity / cost by location -- clustered by approach, separated by location
  (Figs 7.4-7.6, 9.4-9.6; for one approach, Figs 12.1-12.3): one panel per approach.
* totals across stages -- the summary figures (Figs 8.1-8.4, 10.1-10.4, 12.4-12.6): S_tot per
  approach and stage.
"""

from __future__ import annotations

from dataclasses import dataclass

from archmetrics.reports.charts_data import (
    LOCATIONS,
    TOTAL,
    Measure,
    Scope,
    Value,
    stage_labels,
    stage_revisions,
    stage_value,
)
from archmetrics.reports.model import CompareReport

# Okabe & Ito's colour-blind-safe palette
LOCATION_COLOURS = {"base": "#0072B2", "new": "#E69F00", "framework": "#009E73"}
APPROACH_COLOURS = (
    "#D55E00", "#56B4E9", "#009E73", "#CC79A7", "#0072B2", "#E69F00", "#000000", "#F0E442"
)  # fmt: skip
WIDTH, HEIGHT = 10.0, 6.0  # inches, at 100 dpi


@dataclass(frozen=True, slots=True)
class Bars:
    """One legend entry's bars: one value per group of the panel."""

    label: str
    colour: str
    values: tuple[Value, ...]


@dataclass(frozen=True, slots=True)
class Panel:
    title: str
    groups: tuple[str, ...]  # the x tick labels
    bars: tuple[Bars, ...]


@dataclass(frozen=True, slots=True)
class Chart:
    """Everything drawn: titles, axis labels, the panel grid, its size and legend."""

    title: str
    ylabel: str
    xlabel: str
    panels: tuple[Panel, ...]
    shape: tuple[int, int]  # rows, columns
    size: tuple[float, float]  # inches
    legend_title: str


def axis_label(measure: Measure, scope: Scope | None = None) -> str:
    """E.g. "Γ'  scaled code size change" over "[logical lines × λ̂]"; with a ``scope``, its
    symbol (Γ'_tot, Γ'_B+F)."""
    symbol = scope.symbol(measure) if scope else measure.symbol
    return f"{symbol}  {measure.name}\n[{measure.unit}]"


def literal(text: str) -> str:
    """A name or label shown as typed: a ``$`` in it must not start mathtext."""
    return text.replace("$", r"\$")


def stage_ticks(report: CompareReport, stages: tuple[str, ...]) -> tuple[str, ...]:
    """Each stage's label, and under it the revision it measured when that says more
    (``first`` over ``v1.2``; a stage named by its revision once)."""
    return tuple(
        literal(st) if revision is None else f"{literal(st)}\n({literal(revision)})"
        for st, revision in zip(stages, stage_revisions(report, stages), strict=True)
    )


def approaches_of(report: CompareReport) -> str:
    return ", ".join(literal(name) for name, _ in report.series)


def by_location(report: CompareReport, measure: Measure) -> Chart:
    """One panel per approach; stages along x; a bar per location (Figs 7.4-7.6, 12.1-12.3)."""
    stages = stage_labels(report)
    panels = tuple(
        Panel(
            literal(name),
            stage_ticks(report, stages),
            tuple(
                Bars(
                    loc,
                    LOCATION_COLOURS[loc],
                    tuple(stage_value(series, name, st, loc, measure.field) for st in stages),
                )
                for loc in LOCATIONS
            ),
        )
        for name, series in report.series
    )
    cols = len(panels)
    return Chart(
        f"{measure.name.capitalize()} {measure.symbol} by location: {approaches_of(report)}",
        axis_label(measure),
        "stage",
        panels,
        (1, cols),
        (max(WIDTH, 3.2 * cols), HEIGHT),
        "location",
    )


def coupling(report: CompareReport, measures: tuple[Measure, ...]) -> Chart:
    """A row per approach, a column per stage; Δs_a ... Δd_e along x, a bar per location."""
    stages = stage_labels(report)
    panels = tuple(
        Panel(
            f"{literal(name)} · {literal(st)}",
            tuple(m.symbol for m in measures),
            tuple(
                Bars(
                    loc,
                    LOCATION_COLOURS[loc],
                    tuple(stage_value(series, name, st, loc, m.field) for m in measures),
                )
                for loc in LOCATIONS
            ),
        )
        for name, series in report.series
        for st in stages
    )
    rows, cols = len(report.series), len(stages)
    return Chart(
        f"Coupling change by location: {approaches_of(report)}",
        "coupling change\n[links]",
        "",
        panels,
        (rows, cols),
        (max(WIDTH, 3.3 * cols), max(HEIGHT, 1.6 + 2.3 * rows)),
        "location",
    )


def totals(
    report: CompareReport, measures: tuple[Measure, ...], title: str, scope: Scope = TOTAL
) -> Chart:
    """One panel per measure; stages along x; a bar per approach (Figs 8.1-8.4, 12.4-12.6),
    each the sum over the ``scope``'s locations, which the title names."""
    stages = stage_labels(report)
    panels = tuple(
        Panel(
            f"{scope.symbol(m)}  {m.name}" if len(measures) > 1 else "",
            stage_ticks(report, stages),
            tuple(
                Bars(
                    literal(name),
                    APPROACH_COLOURS[i % len(APPROACH_COLOURS)],
                    tuple(scope.value(series, name, st, m.field) for st in stages),
                )
                for i, (name, series) in enumerate(report.series)
            ),
        )
        for m in measures
    )
    single = len(measures) == 1
    return Chart(
        f"{title}, {scope.label}: {approaches_of(report)}",
        axis_label(measures[0], scope) if single else "coupling change\n[links]",
        "stage",
        panels,
        (1, 1) if single else (2, (len(panels) + 1) // 2),
        (WIDTH, HEIGHT),
        "approach",
    )
