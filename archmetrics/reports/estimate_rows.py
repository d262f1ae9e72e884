"""The rows every estimate format shows: per-location figures with one column group per
architecture, the changed elements of each, and the ranking (table, Markdown and CSV agree)."""

from __future__ import annotations

from archmetrics.changeset.accuracy import FigureError
from archmetrics.reports.diff_rows import SUMMARY_ROWS, element_row, number
from archmetrics.reports.model import LOCATION_COLUMNS, EstimateReport, Stage

RANKING_HEADER = ("stage", "rank", "architecture", "E", "Γ'", "ΔVg'")
LABEL = "estimate, not a measurement of the integration"


def stages_named(report: EstimateReport, label: str) -> list[tuple[str, str, Stage]]:
    """(architecture, kind, stage) for every architecture that has a stage ``label``."""
    return [
        (a.name, a.kind, s)
        for a in report.architectures
        for s in a.series.stages
        if s.label == label
    ]


def summary_header(report: EstimateReport, label: str) -> list[str]:
    """``metric``, ``eq.``, then ``ARCH base`` ... ``ARCH total`` for every architecture."""
    names = [name for name, _, _ in stages_named(report, label)]
    return ["metric", "eq.", *(f"{name} {column}" for name in names for column in LOCATION_COLUMNS)]


def summary_rows(report: EstimateReport, label: str) -> list[list[str]]:
    """The diff's per-location rows (thesis tables C-I), one column group per architecture."""
    found = [s.report.summaries() for _, _, s in stages_named(report, label)]
    return [
        [
            text,
            eq,
            *(number(getattr(s[column], field)) for s in found for column in LOCATION_COLUMNS),
        ]
        for field, text, eq in SUMMARY_ROWS
    ]


def element_rows(report: EstimateReport, label: str) -> list[list[str]]:
    """Each architecture's changed elements (the diff's element columns), named by it."""
    return [
        [name, *element_row(e)]
        for name, _, stage in stages_named(report, label)
        for e in stage.report.change.elements
        if e.status.value != "unchanged"
    ]


def ranking_rows(report: EstimateReport) -> list[list[str]]:
    return [
        [
            r.stage,
            str(r.rank),
            r.architecture,
            *(number(v) for v in (r.cost, r.scaled_changes, r.scaled_delta_vg)),
        ]
        for r in report.ranking()
    ]


def notes(report: EstimateReport, label: str) -> list[str]:
    """Every note of a stage once, prefixed with where it applies: ``all``, an architecture
    (all its locations) or an architecture's locations."""
    where: dict[str, dict[str, list[str]]] = {}
    named = stages_named(report, label)
    for name, _, stage in named:
        for column, summary in stage.report.summaries().items():
            for note in summary.notes:
                where.setdefault(note, {}).setdefault(name, []).append(column)
    lines = []
    for note, places in where.items():
        whole = [n for n, cols in places.items() if len(cols) == len(LOCATION_COLUMNS)]
        if len(whole) == len(named) > 1:
            lines.append(f"[all] {note}")
            continue
        parts = [n if n in whole else f"{n} {', '.join(cols)}" for n, cols in places.items()]
        lines.append(f"[{'; '.join(parts)}] {note}")
    return lines


# --actual: the figures a table or Markdown shows per location (JSON and CSV have them all)
ACCURACY_FIGURES: tuple[tuple[str, str], ...] = (
    ("changes", "Γ"),
    ("scaled_changes", "Γ'"),
    ("delta_vg", "ΔVg"),
    ("scaled_delta_vg", "ΔVg'"),
    ("cost", "E"),
    ("loc_post", "λ_post"),
    ("vg_post", "Vg_post"),
    ("delta_s_a", "Δs_a"),
    ("delta_s_e", "Δs_e"),
    ("delta_d_a", "Δd_a"),
    ("delta_d_e", "Δd_e"),
)
ACCURACY_HEADER = ("architecture", "location", "figure", "estimated", "actual", "error", "error %")
ELEMENT_ACCURACY_HEADER = (
    "architecture",
    "element",
    "location",
    "figure",
    "estimated",
    "actual",
    "error",
    "error %",
)


def _percent(value: float | None) -> str:
    return "n/a" if value is None else f"{100 * value:+.0f}%"


def _cells(figure: FigureError) -> list[str]:
    return [
        number(figure.estimated),
        number(figure.actual),
        number(figure.error),
        _percent(figure.relative),
    ]


def accuracy_rows(report: EstimateReport) -> list[list[str]]:
    """Per architecture and location (total last), the main figures against the measured;
    a location with nothing estimated or measured is left out."""
    rows = []
    for name, accuracy in report.accuracy:
        for place in accuracy.locations:
            figures = [place.figure(field) for field, _ in ACCURACY_FIGURES]
            if all(not f.estimated and not f.actual for f in figures):
                continue  # a location empty on both sides (JSON and CSV still have it)
            for field, label in ACCURACY_FIGURES:
                rows.append([name, place.name, label, *_cells(place.figure(field))])
    return rows


def element_accuracy_rows(report: EstimateReport) -> list[list[str]]:
    """Per architecture, each element's figures that the estimate got wrong."""
    return [
        [name, element.name, element.location, figure.figure, *_cells(figure)]
        for name, accuracy in report.accuracy
        for element in accuracy.elements
        for figure in element.figures
        if figure.error != 0
    ]
