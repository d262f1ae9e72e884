"""How good a plan was: an estimate's figures against the measured change (pure).

Per location (and the total) every numeric summary figure, and per element its Γ counts and
its metrics after; each with ``error = estimated − actual`` and ``relative = error / actual``
(undefined, None, when the actual figure is 0 or either side has no value). docs/estimate.md.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from archmetrics.changeset.model import (
    SUMMARY_FIELDS,
    ChangeReport,
    ElementChange,
    Metrics,
    Summary,
)

LOCATION_FIGURES = tuple(f for f in SUMMARY_FIELDS if f != "notes")
ELEMENT_FIGURES = (
    "added",
    "removed",
    "modified",
    "changes",
    "loc",
    "vg",
    "s_a",
    "s_e",
    "d_a",
    "d_e",
)
"""Per element: Γ_A, Γ_R, Γ_M, Γ, then λ, v_g and coupling after the change."""


@dataclass(frozen=True, slots=True)
class FigureError:
    """One figure estimated and measured, and how far apart they are."""

    figure: str
    estimated: float | None
    actual: float | None

    @property
    def error(self) -> float | None:
        if self.estimated is None or self.actual is None:
            return None
        return self.estimated - self.actual

    @property
    def relative(self) -> float | None:
        error = self.error
        return None if error is None or not self.actual else error / abs(self.actual)


@dataclass(frozen=True, slots=True)
class Accuracy:
    """Of one place (a location, the total, or an element): its figures' errors."""

    name: str
    location: str
    figures: tuple[FigureError, ...]

    def figure(self, name: str) -> FigureError:
        return next(f for f in self.figures if f.figure == name)


@dataclass(frozen=True, slots=True)
class ChangeAccuracy:
    """An estimate against the measured change: per location and total, per element."""

    locations: tuple[Accuracy, ...]  # base, new, framework, total
    elements: tuple[Accuracy, ...]  # changed on either side, or estimated wrong


def _value(summary: Summary, field: str) -> float | None:
    value: float | None = getattr(summary, field)  # an int where the figure is a count
    return value


def _summaries(report: ChangeReport) -> dict[str, Summary]:
    found = {loc.value: summary for loc, summary in report.locations}
    found["total"] = report.total
    return found


def _element_values(change: ElementChange | None) -> Mapping[str, float | None]:
    """An element's figures; one that does not exist on a side changed nothing there."""
    counts = (0, 0, 0) if change is None else (change.added, change.removed, change.modified)
    post: Metrics | None = change.post if change else None
    values: dict[str, float | None] = dict(
        zip(("added", "removed", "modified"), counts, strict=True)
    )
    values["changes"] = sum(counts)
    for field in ("loc", "vg", "s_a", "s_e", "d_a", "d_e"):
        values[field] = None if post is None else getattr(post, field)
    return values


def _changed(change: ElementChange | None) -> bool:
    return change is not None and change.status.value != "unchanged"


def compare_change(estimated: ChangeReport, actual: ChangeReport) -> ChangeAccuracy:
    """Every figure of ``estimated`` against the same figure of ``actual``."""
    planned, measured = _summaries(estimated), _summaries(actual)
    locations = tuple(
        Accuracy(
            name,
            name,
            tuple(
                FigureError(f, _value(planned[name], f), _value(measured[name], f))
                for f in LOCATION_FIGURES
            ),
        )
        for name in planned
    )
    mine = {e.element: e for e in estimated.elements}
    theirs = {e.element: e for e in actual.elements}
    elements = []
    for name in sorted(set(mine) | set(theirs)):
        ours, real = mine.get(name), theirs.get(name)
        a, b = _element_values(ours), _element_values(real)
        figures = tuple(FigureError(f, a[f], b[f]) for f in ELEMENT_FIGURES)
        if _changed(ours) or _changed(real) or any(a[f] != b[f] for f in ELEMENT_FIGURES):
            where = (real or ours).location.value  # type: ignore[union-attr]
            elements.append(Accuracy(name, where, figures))
    return ChangeAccuracy(locations, tuple(elements))
